"""A simulated CiA 402 servo drive on the bus, for the real-bus tests: the
SDO server, heartbeat, NMT and PDO glue of slave401.Slave401 (python-canopen's
LocalNode) with a CiA 402 dictionary, the drive's power state machine
written from the standard's transition table (IEC 61800-7-201 / CiA 402),
and a motor model stepped at each SYNC:

  CSP (8)  the position follows the target position of the previous SYNC
  CSV (9)  the position integrates the target velocity
  PP (1)   new set-point handshake (controlword bit 4, statusword bit 12),
           a trapeze at the profile velocity and acceleration
  PV (3)   the speed ramps to the target velocity at the profile acceleration
  HM (6)   method 35/37: the present position becomes 0 (plus home_at)

A load can be blocked (stuck): in CSP the following error then exceeds
0x6065 and the drive faults with EMCY 0x8611, as a real drive set to fault
on a following error does.  The
controlword is taken at each SYNC (from the RPDO) and at each SDO write, so
a master using SDO only (python-canopen's BaseNode402) drives it as well.
"""
import time

from canopen.objectdictionary import ODVariable
from canopen.objectdictionary import datatypes as dt

from slave401 import Slave401, build_od

CIA402_TYPE = 0x00020192          # CiA 402, servo drive
SW_STATE = {1: 0x00, 2: 0x40, 3: 0x21, 4: 0x23, 5: 0x27, 6: 0x07, 7: 0x0F, 8: 0x08}
STATE_NAMES = {1: "NOT READY TO SWITCH ON", 2: "SWITCH ON DISABLED", 3: "READY TO SWITCH ON",
               4: "SWITCHED ON", 5: "OPERATION ENABLED", 6: "QUICK STOP ACTIVE",
               7: "FAULT REACTION ACTIVE", 8: "FAULT"}


def _var(name, index, dtype, default=0, access="rw"):
    v = ODVariable(name, index, 0)
    v.data_type = dtype
    v.access_type = access
    v.default = default
    return v


def build_od402(node_id):
    """The CiA 401 skeleton's communication part with the CiA 402 objects."""
    od = build_od(node_id, CIA402_TYPE)
    for index in (0x6000, 0x6200, 0x6401, 0x6411):
        del od.indices[index]
        del od.names[[n for n, o in od.names.items() if o.index == index][0]]
    for name, index, dtype, default in (
            ("error code", 0x603F, dt.UNSIGNED16, 0),
            ("controlword", 0x6040, dt.UNSIGNED16, 0),
            ("statusword", 0x6041, dt.UNSIGNED16, 0),
            ("quick stop option code", 0x605A, dt.INTEGER16, 2),
            ("modes of operation", 0x6060, dt.INTEGER8, 0),
            ("modes of operation display", 0x6061, dt.INTEGER8, 0),
            ("position actual value", 0x6064, dt.INTEGER32, 0),
            ("following error window", 0x6065, dt.UNSIGNED32, 1000),
            ("velocity actual value", 0x606C, dt.INTEGER32, 0),
            ("target position", 0x607A, dt.INTEGER32, 0),
            ("profile velocity", 0x6081, dt.UNSIGNED32, 10000),
            ("profile acceleration", 0x6083, dt.UNSIGNED32, 100000),
            ("profile deceleration", 0x6084, dt.UNSIGNED32, 100000),
            ("homing method", 0x6098, dt.INTEGER8, 35),
            ("target velocity", 0x60FF, dt.INTEGER32, 0),
            ("supported drive modes", 0x6502, dt.UNSIGNED32, 0x1A5)):
        od.add_object(_var(name, index, dtype, default))
    return od


class Drive402(Slave401):
    """A CiA 402 drive on a canopen.Network (see the module's text)."""

    def __init__(self, network, node_id, home_at=0):
        self.home_at = home_at
        super().__init__(network, node_id, device_type=CIA402_TYPE, od=build_od402(node_id))
        self.node.add_write_callback(self._on_write)
        self.on_sync = Drive402._step

    # -- the power state machine, from the standard's table -----------------
    def reset_drive(self):
        """Power-on: transitions 0 and 1, to Switch on disabled."""
        self.st = 2
        self.pcw = 0
        self.trans = []          # transitions taken, CiA 402 numbers
        self.refuse = set()      # transitions this drive will not take
        self.fault_code = 0
        self.fault_hold = False  # a fault reset does not clear it while True
        self.stuck = False
        self.pos = 0.0
        self.vel = 0.0
        self.pp_target = None
        self.pp_ack = False
        self.home_phase = 0
        self.home_done = False
        self.last = None
        self.mode_disp = 0
        self._publish()

    def boot(self, comm_only=False):
        super().boot(comm_only)
        if not comm_only:
            self.reset_drive()

    def _go(self, n, to):
        if n in self.refuse:
            return
        self.trans.append(n)
        self.st = to

    def command(self, cw):
        """The controlword cw arrives: the transition it asks for, if any."""
        st, rising7 = self.st, cw & 0x80 and not self.pcw & 0x80
        self.pcw = cw
        if st == 8:
            if rising7 and not self.fault_hold:
                self.fault_code = 0
                self.set(0x603F, 0, 0)
                self._go(15, 2)
                if self.st == 2:
                    self.network.send_message(0x80 + self.id, bytes(8))   # EMCY error reset
        elif cw & 0x80 or st in (1, 7):
            pass
        elif not cw & 0x02:                                  # disable voltage
            n = {3: 7, 4: 10, 5: 9, 6: 12}.get(st)
            if n:
                self._go(n, 2)
        elif cw & 0x06 == 0x02:                              # quick stop
            n = {3: (7, 2), 4: (10, 2), 5: (11, 6)}.get(st)
            if n:
                self._go(*n)
        elif cw & 0x07 == 0x06:                              # shutdown
            n = {2: 2, 4: 6, 5: 8}.get(st)
            if n:
                self._go(n, 3)
        elif cw & 0x0F == 0x07:                              # switch on / disable operation
            n = {3: (3, 4), 5: (5, 4)}.get(st)
            if n:
                self._go(*n)
        elif cw & 0x0F == 0x0F:                              # enable operation
            if st == 3:                                      # switch on + enable operation
                self._go(3, 4)
                if self.st == 4:
                    self._go(4, 5)
            elif st == 4:
                self._go(4, 5)
            elif st == 6 and self.get(0x605A) >= 5:
                self._go(16, 5)
        self._publish()

    def fault(self, code=0x5530, hold=False):
        """A fault: 13 then 14, EMCY with code, 0x603F set."""
        if self.st in (7, 8):
            return
        self.fault_code = code
        self.fault_hold = hold
        self.set(0x603F, 0, code)
        self.trans += [13, 14]
        self.st = 8
        self.network.send_message(0x80 + self.id, code.to_bytes(2, "little") + bytes([0x80]) + bytes(5))
        self._publish()

    def _on_write(self, index, subindex, od, data):
        if index == 0x6040:
            with self.lock:
                self.node.data_store.setdefault(index, {})[0] = bytes(data)
                self.command(int.from_bytes(data, "little"))

    # -- the motor ------------------------------------------------------------
    def _step(self):
        now = time.monotonic()
        h = 0.0 if self.last is None else min(now - self.last, 0.1)
        self.last = now
        with self.lock:
            self.command(self.get(0x6040))
            cw = self.get(0x6040)
            mode = self.get(0x6060)
            p0 = self.pos
            if self.st != 5:
                self.pp_target, self.pp_ack, self.vel = None, False, 0.0
                self.home_phase = 0
            elif self.mode_disp == 8:
                tgt = self.get(0x607A)
                if not self.stuck:
                    self.pos = float(tgt)
                win = self.get(0x6065)
                if win and abs(tgt - self.pos) > win:
                    self.fault(0x8611)
            elif self.mode_disp == 9:
                if not self.stuck:
                    self.pos += self.get(0x60FF) * h
            elif self.mode_disp == 1:
                if cw & 0x10 and not self.pp_ack:
                    self.pp_target = float(self.get(0x607A))
                    self.pp_ack = True
                elif not cw & 0x10:
                    self.pp_ack = False
                if cw & 0x100:
                    self.pp_target = self.pos if self.pp_target is not None else None
                self._trapeze(h)
            elif self.mode_disp == 3:
                vt = 0.0 if cw & 0x100 else float(self.get(0x60FF))
                a = self.get(0x6084 if cw & 0x100 or abs(vt) < abs(self.vel) else 0x6083)
                self.vel += max(-a * h, min(a * h, vt - self.vel))
                self.pos += self.vel * h
            elif self.mode_disp == 6:
                if cw & 0x10 and self.home_phase == 0:
                    self.home_phase = 1
                    self.home_left = 3
                elif self.home_phase == 1:
                    self.home_left -= 1
                    if self.home_left <= 0:
                        self.pos = float(self.home_at)
                        self.home_phase = 2
                elif not cw & 0x10:
                    self.home_phase = 0
            if self.mode_disp not in (3, 1):
                self.vel = (self.pos - p0) / h if h > 0 else 0.0
            self.mode_disp = mode
            self._publish()

    def _trapeze(self, h):
        if self.pp_target is None or h <= 0:
            return
        d = self.pp_target - self.pos
        vmax = float(self.get(0x6081))
        a = float(self.get(0x6083))
        vstop = (2 * a * abs(d)) ** 0.5
        vt = max(-vmax, min(vmax, vstop if d > 0 else -vstop))
        self.vel += max(-a * h, min(a * h, vt - self.vel))
        step = self.vel * h
        if abs(step) >= abs(d) or abs(d) < 0.5:
            self.pos, self.vel = self.pp_target, 0.0
        else:
            self.pos += step

    def _publish(self):
        sw = SW_STATE[self.st] | 0x0200 | (0x10 if self.st in (4, 5, 6) else 0)
        if self.st == 5:
            if self.mode_disp == 8:
                sw |= 0x1000
            elif self.mode_disp == 1:
                if self.pp_ack:
                    sw |= 0x1000
                elif self.pp_target is None or self.pos == self.pp_target:
                    sw |= 0x0400
            elif self.mode_disp == 3:
                vt = 0.0 if self.get(0x6040) & 0x100 else self.get(0x60FF)
                if abs(self.vel - vt) < 0.5:
                    sw |= 0x0400
            elif self.mode_disp == 6 and self.home_phase == 2:
                sw |= 0x1400
        with self.lock:
            self.set(0x6041, 0, sw)
            self.set(0x6061, 0, self.mode_disp)
            p = int(round(self.pos))
            self.set(0x6064, 0, (p + 2**31) % 2**32 - 2**31)
            self.set(0x606C, 0, int(round(self.vel)))

    @property
    def state_name(self):
        return STATE_NAMES[self.st]


def main():
    """Run simulated drives on a CAN interface until SIGINT/SIGTERM:
        python3 tests/canopen/drive402.py [--interface vcan0] NODE_ID..."""
    import argparse
    import signal

    from slave401 import connect
    p = argparse.ArgumentParser(description="simulated CiA 402 drives (CSP, CSV, PP, PV, homing)")
    p.add_argument("--interface", default="vcan0")
    p.add_argument("nodes", nargs="+", type=int)
    a = p.parse_args()
    try:
        net = connect(a.interface)
    except OSError as e:
        raise SystemExit(f"drive402: CAN interface {a.interface}: {e} (docs/drives.md says how to make a vcan0)")
    drives = [Drive402(net, n) for n in a.nodes]
    print(f"drive402: {len(drives)} simulated CiA 402 drive(s) on {a.interface}: nodes "
          + ", ".join(str(n) for n in a.nodes), flush=True)
    signal.sigwait({signal.SIGINT, signal.SIGTERM})
    net.disconnect()


if __name__ == "__main__":
    import signal as _s
    _s.pthread_sigmask(_s.SIG_BLOCK, {_s.SIGINT, _s.SIGTERM})
    main()
