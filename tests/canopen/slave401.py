"""CiA 401 I/O module peers for the real-bus tests, on python-canopen.

python-canopen's LocalNode gives the SDO server, the heartbeat producer and
the object dictionary; the glue here adds what a CiA 401 module does beyond
that: NMT reset commands restore the dictionary and re-send the boot-up,
received RPDOs are unpacked into the dictionary by their mapping, and each
SYNC is answered with the synchronous TPDOs. PDO packing is done here
independently of the master's C code (plain integer arithmetic).
"""
import os
import subprocess
import threading
import time

import can
import canopen
from canopen.objectdictionary import ODArray, ODRecord, ODVariable, ObjectDictionary
from canopen.objectdictionary import datatypes as dt

CIA401_TYPE = 0x00000191


def var(name, index, sub, dtype, access="rw", default=0):
    v = ODVariable(name, index, sub)
    v.data_type = dtype
    v.access_type = access
    v.default = default
    return v


def array(od, name, index, n, dtype, access="rw"):
    a = ODArray(name, index)
    a.add_member(var("count", index, 0, dt.UNSIGNED8, "ro", n))
    for s in range(1, n + 1):
        a.add_member(var(f"{name} {s}", index, s, dtype, access, 0))
    od.add_object(a)


def comm_objects(device_type, device_name):
    """A dictionary with CiA 301's communication objects a small node has:
    device type, error register, heartbeat, guard time and life time
    factor (written by the master), device name."""
    od = ObjectDictionary()
    od.add_object(var("device type", 0x1000, 0, dt.UNSIGNED32, "ro", device_type))
    od.add_object(var("error register", 0x1001, 0, dt.UNSIGNED8, "ro", 0))
    od.add_object(var("producer heartbeat time", 0x1017, 0, dt.UNSIGNED16, "rw", 0))
    od.add_object(var("guard time", 0x100C, 0, dt.UNSIGNED16, "rw", 0))
    od.add_object(var("life time factor", 0x100D, 0, dt.UNSIGNED8, "rw", 0))
    name = ODVariable("device name", 0x1008, 0)
    name.data_type = dt.VISIBLE_STRING
    name.access_type = "const"
    name.default = device_name
    od.add_object(name)
    return od


def build_od(node_id, device_type=CIA401_TYPE, encoder=False):
    """A CiA 401 dictionary: 8 digital input/output bytes, 4 analog inputs and
    outputs (INTEGER16); with encoder=True also 0x2000 an INTEGER32 count."""
    od = comm_objects(device_type, "CiA401 slave")
    for base, fc in ((0x1400, 0x200), (0x1800, 0x180)):
        for i in range(4):
            r = ODRecord(f"PDO comm {i}", base + i)
            r.add_member(var("highest sub", base + i, 0, dt.UNSIGNED8, "ro", 2))
            # power-on: PDO1/2 valid on their default COB-IDs, 3/4 invalid
            cobid = fc + 0x100 * i + node_id + (0 if i < 2 else 0x80000000)
            r.add_member(var("COB-ID", base + i, 1, dt.UNSIGNED32, "rw", cobid))
            r.add_member(var("transmission type", base + i, 2, dt.UNSIGNED8, "rw", 255))
            od.add_object(r)
    for base in (0x1600, 0x1A00):
        for i in range(4):
            r = ODRecord(f"PDO map {i}", base + i)
            r.add_member(var("count", base + i, 0, dt.UNSIGNED8, "rw", 0))
            for s in range(1, 9):
                r.add_member(var(f"object {s}", base + i, s, dt.UNSIGNED32, "rw", 0))
            od.add_object(r)
    array(od, "digital inputs", 0x6000, 8, dt.UNSIGNED8)
    array(od, "digital outputs", 0x6200, 8, dt.UNSIGNED8)
    array(od, "analog inputs", 0x6401, 4, dt.INTEGER16)
    array(od, "analog outputs", 0x6411, 4, dt.INTEGER16)
    if encoder:
        od.add_object(var("encoder count", 0x2000, 0, dt.INTEGER32, "rw", 0))
    return od


class Slave401:
    """A CiA 401 module on a canopen.Network."""

    def __init__(self, network, node_id, device_type=CIA401_TYPE, encoder=False, od=None):
        self.id = node_id
        self.network = network
        self.lock = threading.RLock()
        self.node = canopen.LocalNode(node_id, od or build_od(node_id, device_type, encoder))
        network.add_node(self.node)
        # replace the library's NMT handling: ours restores the dictionary
        # and sends the boot-up, as a real module does
        network.unsubscribe(0, self.node.nmt.on_command)
        network.subscribe(0, self._on_nmt)
        network.subscribe(0x080, self._on_sync)
        for i in range(4):
            network.subscribe(0x200 + 0x100 * i + node_id, self._on_rpdo)
        # node guarding: python-canopen drops remote frames, so the RTRs are
        # taken from python-can directly; the answer is the NMT state with
        # the toggle bit, which starts at 0 after each boot
        self.guard_answer = True
        self.guard_rtrs = 0
        self.toggle = 0
        network.notifier.add_listener(_GuardListener(self))
        self.short_tpdo = 0          # > 0: TPDOs cut to this many bytes
        self.syncs = 0
        self.rpdos = 0
        self.on_sync = None          # hook run before the TPDOs go out
        self.boot()

    # -- dictionary access -------------------------------------------------
    def get(self, index, sub=0):
        obj = self.node._find_object(index, sub)
        data = self.node.get_data(index, sub)
        return obj.decode_raw(data)

    def set(self, index, sub, value):
        obj = self.node._find_object(index, sub)
        with self.lock:
            self.node.data_store.setdefault(index, {})[sub] = obj.encode_raw(value)

    def _u32(self, index, sub):
        return int.from_bytes(self.node.get_data(index, sub), "little")

    # -- NMT ---------------------------------------------------------------
    @property
    def state(self):
        return self.node.nmt._state

    def boot(self, comm_only=False):
        """Power-on / reset: dictionary to defaults, boot-up, pre-operational."""
        nmt = self.node.nmt
        nmt.stop_heartbeat()
        with self.lock:
            if comm_only:
                for index in [i for i in self.node.data_store if 0x1000 <= i < 0x2000]:
                    del self.node.data_store[index]
            else:
                self.node.data_store.clear()
        nmt._state = 0
        self.toggle = 0
        self.network.send_message(0x700 + self.id, [0])      # boot-up
        nmt._state = 127
        hb = self.get(0x1017)
        if hb:
            nmt.start_heartbeat(hb)

    def _on_nmt(self, can_id, data, timestamp):
        if len(data) < 2 or data[1] not in (0, self.id):
            return
        cmd = data[0]
        if cmd in (0x81, 0x82):
            self.boot(comm_only=(cmd == 0x82))
            return
        states = {0x01: 5, 0x02: 4, 0x80: 127}
        if cmd in states:
            self.node.nmt._state = states[cmd]
            # a new periodic task with the new state, not an update of the
            # running one: on a loaded host the kernel's modified task was
            # seen to send once and then stop (node silent, "lost")
            hb = self.get(0x1017)
            if hb:
                self.node.nmt.start_heartbeat(hb)
            else:
                self.node.nmt.update_heartbeat()

    def stop_heartbeat(self):
        self.node.nmt.stop_heartbeat()

    # -- PDOs ----------------------------------------------------------------
    def _mapping(self, base, i):
        n = self._u32(base + i, 0)
        out = []
        for s in range(1, n + 1):
            m = self._u32(base + i, s)
            out.append((m >> 16, (m >> 8) & 0xFF, m & 0xFF))
        return out

    def _on_rpdo(self, can_id, data, timestamp):
        if self.state != 5:
            return
        for i in range(4):
            cobid = self._u32(0x1400 + i, 1)
            if cobid & 0x80000000 or (cobid & 0x7FF) != can_id:
                continue
            word = int.from_bytes(bytes(data), "little")
            off = 0
            with self.lock:
                for index, sub, bits in self._mapping(0x1600, i):
                    raw = (word >> off) & ((1 << bits) - 1)
                    obj = self.node._find_object(index, sub)
                    nbytes = max(1, (len(obj) + 7) // 8)
                    self.node.data_store.setdefault(index, {})[sub] = raw.to_bytes(nbytes, "little")
                    off += bits
            self.rpdos += 1

    def _on_sync(self, can_id, data, timestamp):
        if can_id != 0x080:
            return
        self.syncs += 1
        if self.state != 5:
            return
        if self.on_sync:
            self.on_sync(self)
        for i in range(4):
            cobid = self._u32(0x1800 + i, 1)
            trans = self._u32(0x1800 + i, 2)
            if cobid & 0x80000000 or not 1 <= trans <= 240:
                continue
            word, off = 0, 0
            with self.lock:
                for index, sub, bits in self._mapping(0x1A00, i):
                    raw = int.from_bytes(self.node.get_data(index, sub), "little")
                    word |= (raw & ((1 << bits) - 1)) << off
                    off += bits
            data = word.to_bytes((off + 7) // 8, "little")
            if self.short_tpdo:                     # a broken node: TPDOs cut short
                data = data[:self.short_tpdo]
            self.network.send_message(cobid & 0x7FF, data)


class _GuardListener(can.Listener):
    def __init__(self, slave):
        self.slave = slave

    def on_message_received(self, msg):
        s = self.slave
        if not msg.is_remote_frame or msg.arbitration_id != 0x700 + s.id:
            return
        s.guard_rtrs += 1
        # not while booting (state 0): a real node answers from
        # pre-operational on, and a state 0 answer reads as a boot-up
        if s.guard_answer and s.state != 0:
            s.network.send_message(0x700 + s.id, [s.state | s.toggle])
            s.toggle ^= 0x80


class Axis(Slave401):
    """A CAN-driven simulated axis: analog output 1 (0x6411:01, 32767 =
    +10 V) is the speed reference of a drive reaching `maxvel` counts/s at
    10 V; the position is integrated into the INTEGER32 encoder count
    0x2000 at every SYNC; the cam input 0x6000:01 bit 0 is on while the count
    lies within [cam_lo, cam_hi]."""

    def __init__(self, network, node_id, maxvel=40000.0, cam=(10000, 12000)):
        super().__init__(network, node_id, encoder=True)
        self.maxvel = maxvel
        self.cam = cam
        self.pos = 0.0
        self.last = None
        self.on_sync = Axis._integrate

    def _integrate(self):
        now = time.monotonic()
        if self.last is not None:
            dac = self.get(0x6411, 1)
            self.pos += dac / 32767.0 * self.maxvel * (now - self.last)
        self.last = now
        count = int(round(self.pos))
        count = (count + 2**31) % 2**32 - 2**31
        self.set(0x2000, 0, count)
        self.set(0x6000, 1, 1 if self.cam[0] <= count <= self.cam[1] else 0)


def connect(channel="vcan0"):
    net = canopen.Network()
    net.connect(interface="socketcan", channel=channel)
    return net


def reference_zero_after(rpdo, t_last, t_next, life_s, cycle_s):
    """Seed 000's reaction to a lost node, counted on the recorded reference
    RPDOs (rpdo: [(kernel time, data)]) between the node's last good
    guarding answer t_last and its next t_next: the master dates that answer
    by its arrival and sees the loss in the first cycle that starts more
    than the life time later, and APOSSAXIS puts out 0 in that very call; so
    the (life / cycle + 1)th RPDO after the answer is 0, or by the scan's
    jitter the next: counted in the PLC's cycles (one RPDO each), a stalled
    plcrt cannot fail it.  Returns (ok, text) for the report."""
    limit = round(life_s / cycle_s) + 2
    after = [(t, d) for t, d in rpdo if t_last < t < t_next]
    moving = [t for t, d in rpdo if t_last - 0.2 < t < t_last and int.from_bytes(d[:2], "little", signed=True)]
    bad = [k + 1 for k, (t, d) in enumerate(after) if k + 1 >= limit and any(d)]
    first0 = max([k + 2 for k, (t, d) in enumerate(after) if any(d)], default=1)
    if first0 > len(after):
        return False, "no zero RPDO"
    ms0 = (after[first0 - 1][0] - t_last) * 1000
    return (len(after) > limit and not bad and bool(moving),
            f"the reference 0 from the {first0}th RPDO after the last answer, {ms0:.0f} ms after it (limit: "
            f"the {limit}th, life time {life_s * 1000:.0f} ms / cycle {cycle_s * 1000:.0f} ms + 2); "
            + (f"non-zero at RPDOs {bad[:5]}" if bad else f"{len(after) - limit + 1} RPDOs from the limit on, all 0")
            + f"; {len(moving)} non-zero in the 200 ms before")


class CanDump:
    """candump -L of the bus into path while the test runs; stop() ends the
    recording, frames(cob_id) reads it back with the kernel's timestamps,
    and the trace is kept only when a test failed (close(keep))."""

    def __init__(self, path, channel="vcan0"):
        self.path = path
        self.p = subprocess.Popen(["candump", "-L", channel], stdout=open(path, "w"))

    def stop(self):
        if self.p.poll() is None:
            self.p.terminate()
            self.p.wait()

    def frames(self, cob_id):
        """[(time, data bytes)] of every frame with this COB-ID, in order."""
        self.stop()
        out = []
        with open(self.path) as f:
            for line in f:
                parts = line.split()
                if len(parts) != 3 or "#" not in parts[2]:
                    continue
                ident, data = parts[2].split("#", 1)
                if data.startswith("R"):            # a remote frame (node guarding RTR)
                    continue
                if int(ident, 16) == cob_id:
                    out.append((float(parts[0].strip("()")), bytes.fromhex(data)))
        return out

    def outputs_after_loss(self, node, t_stop, cob_ids):
        """How the master made node's outputs safe, read from the bus itself
        (kernel timestamps, whatever the speed of the script): the node's last
        operational heartbeat before t_stop (time.time() when its heartbeat
        was stopped), and for each COB-ID the first frame after it from which
        every frame up to the node's next boot-up is all zeros. Returns (last
        heartbeat or None, seconds from it to the latest such first zero frame
        or None if some COB-ID never turned to zeros, frames seen)."""
        hb = self.frames(0x700 + node)
        beats = [t for t, d in hb if d == b"\x05" and t < t_stop]
        if not beats:
            return None, None, 0
        last = beats[-1]
        boot = min([t for t, d in hb if d == b"\x00" and t > t_stop], default=float("inf"))
        worst, seen = 0.0, 0
        for cid in cob_ids:
            fr = [(t, d) for t, d in self.frames(cid) if last < t < boot]
            seen += len(fr)
            k = len(fr)
            while k > 0 and not any(fr[k - 1][1]):
                k -= 1
            if k == len(fr):
                return last, None, seen
            worst = max(worst, fr[k][0] - last)
        return last, worst, seen

    def outputs_safe_check(self, node, t_stop, hb_cons, cob_ids):
        """(ok, detail) for the deadline: node's RPDOs (cob_ids) turn to zeros
        within two consumer times of its last heartbeat and stay so."""
        last, dt, seen = self.outputs_after_loss(node, t_stop, cob_ids)
        if last is None:
            return False, "no heartbeat recorded"
        if dt is None:
            return False, f"RPDOs to node {node} not zero until it boots again ({seen} seen)"
        return dt <= 2 * hb_cons, (f"RPDOs to node {node} zero from {dt * 1000:.0f} ms after its last "
                                   f"heartbeat on, limit {2 * hb_cons * 1000:.0f} ms ({seen} RPDOs until it boots again)")

    def close(self, keep):
        self.stop()
        if keep:
            print(f"candump trace kept: {self.path}")
        else:
            os.remove(self.path)
