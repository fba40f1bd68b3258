"""A CiA 406 rotary encoder peer for the real-bus tests, on python-canopen
(the glue of slave401.Slave401: NMT with boot-up, node guarding, TPDOs on
SYNC), and the motor it measures.

Its dictionary is the CiA 406 one as a plain encoder ships it: device type
0x00010196 (profile 406, type 1: a rotary encoder), 0x6004 position value
(UNSIGNED32), 0x6000 operating parameters, 0x6001 measuring units per
revolution, 0x6002 total measuring range; TPDO1 maps 0x6004 and is
asynchronous (transmission type 254), TPDO2 maps 0x6004 and answers each
SYNC (type 1), as CiA 406 predefines them.  The position is the motor's,
an axis whose speed is analog output 1 of a CiA 401 module on the same bus
(a drive reaching `maxvel` counts/s at 10 V): the test bench's amplifier
and motor, with the encoder on its shaft.  It is kept in Python apart from
the dictionary, so that a reset of the node (which restores the defaults,
as a real one does) does not lose it; it is integrated at each SYNC on the
SYNC frames' kernel timestamps before the TPDO goes out, and sent wrapping
at 2^32 as the encoder's 32-bit value does.
"""
from canopen.objectdictionary import ODRecord
from canopen.objectdictionary import datatypes as dt

from slave401 import Slave401, comm_objects, var

CIA406_TYPE = 0x00010196


def build_od406(node_id):
    od = comm_objects(CIA406_TYPE, "CiA406 encoder")
    for base, fc in ((0x1400, 0x200), (0x1800, 0x180)):
        for i in range(4):
            r = ODRecord(f"PDO comm {i}", base + i)
            r.add_member(var("highest sub", base + i, 0, dt.UNSIGNED8, "ro", 2))
            cobid = fc + 0x100 * i + node_id + (0 if (base == 0x1800 and i < 2) else 0x80000000)
            r.add_member(var("COB-ID", base + i, 1, dt.UNSIGNED32, "rw", cobid))
            trans = (254 if i == 0 else 1) if base == 0x1800 else 255
            r.add_member(var("transmission type", base + i, 2, dt.UNSIGNED8, "rw", trans))
            od.add_object(r)
    for base in (0x1600, 0x1A00):
        for i in range(4):
            r = ODRecord(f"PDO map {i}", base + i)
            mapped = base == 0x1A00 and i < 2
            r.add_member(var("count", base + i, 0, dt.UNSIGNED8, "rw", 1 if mapped else 0))
            for s in range(1, 9):
                r.add_member(var(f"object {s}", base + i, s, dt.UNSIGNED32, "rw",
                                 0x60040020 if mapped and s == 1 else 0))
            od.add_object(r)
    od.add_object(var("operating parameters", 0x6000, 0, dt.UNSIGNED16, "rw", 0))
    od.add_object(var("measuring units per revolution", 0x6001, 0, dt.UNSIGNED32, "rw", 4096))
    od.add_object(var("total measuring range", 0x6002, 0, dt.UNSIGNED32, "rw", 0))
    od.add_object(var("position value", 0x6004, 0, dt.UNSIGNED32, "ro", 0))
    return od


class Encoder406(Slave401):
    """A CiA 406 encoder on the shaft of a motor driven by analog output 1
    of `module` (a Slave401): pos counts (float, unwrapped).  The motor
    moves on bus time: at each SYNC by the reference it had since the
    previous one times the time between the two SYNC frames' kernel
    timestamps, so that a slow test process does not bend the plant."""

    def __init__(self, network, node_id, module, pos=0, maxvel=40000.0):
        self.pos = float(pos)
        self.module = module
        self.maxvel = maxvel
        self.last = None
        super().__init__(network, node_id, od=build_od406(node_id))
        self.on_sync = Encoder406._show

    @property
    def value(self):
        """the position value as the encoder sends it: 32 bits, unsigned"""
        return int(round(self.pos)) % 2**32

    def _on_sync(self, can_id, data, timestamp):
        # the motor turns whatever the encoder's NMT state
        if can_id == 0x080:
            with self.lock:
                if self.last is not None:
                    dac = self.module.get(0x6411, 1)
                    self.pos += dac / 32767.0 * self.maxvel * (timestamp - self.last)
                self.last = timestamp
        super()._on_sync(can_id, data, timestamp)

    def _show(self):
        self.set(0x6004, 0, self.value)

    def turn(self, counts):
        """turned by hand"""
        with self.lock:
            self.pos += counts
