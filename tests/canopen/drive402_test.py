"""The simulated CiA 402 drive (drive402.Drive402) checked before plcrt
drives it, on vcan0 inside a kernel with CAN (tests/canopen/bus_run.sh):

1. its state machine against the standard's transition table, written out
   here from CiA 402 / IEC 61800-7-201 (from state, controlword, to state,
   transition number), and its statusword against the standard's patterns;
2. against python-canopen's BaseNode402, an independent master's reading of
   the same state machine, over SDO on the bus: power up, quick stop,
   disable, a fault and its reset, the mode display, homing.

    $PY tests/canopen/drive402_test.py OUT_DIR
"""
import os
import sys

import logging

import canopen

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from drive402 import Drive402, build_od402  # noqa: E402
from slave401 import connect  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Report, wait_for  # noqa: E402

report = Report("canopen_drive402")
# BaseNode402 warns at every statusword it reads by SDO: that is the way chosen here
logging.getLogger("canopen.profiles.p402").setLevel(logging.ERROR)

# CiA 402 states and the statusword pattern (mask, value) of each
SWD, RTSO, SO, OE, QSA, FRA, FAULT, NRTSO = 2, 3, 4, 5, 6, 7, 8, 1
PATTERN = {NRTSO: (0x4F, 0x00), SWD: (0x4F, 0x40), RTSO: (0x6F, 0x21), SO: (0x6F, 0x23),
           OE: (0x6F, 0x27), QSA: (0x6F, 0x07), FRA: (0x4F, 0x0F), FAULT: (0x4F, 0x08)}
# the transition table: (from, controlword, to, transitions)
SHUTDOWN, SWITCH_ON, DISABLE_VOLTAGE, QUICK_STOP, DISABLE_OP, ENABLE_OP = 0x06, 0x07, 0x00, 0x02, 0x07, 0x0F
TABLE = [
    (SWD, SHUTDOWN, RTSO, [2]),
    (RTSO, SWITCH_ON, SO, [3]),
    (RTSO, ENABLE_OP, OE, [3, 4]),          # switch on + enable operation
    (SO, ENABLE_OP, OE, [4]),
    (OE, DISABLE_OP, SO, [5]),
    (SO, SHUTDOWN, RTSO, [6]),
    (RTSO, DISABLE_VOLTAGE, SWD, [7]),
    (RTSO, QUICK_STOP, SWD, [7]),
    (OE, SHUTDOWN, RTSO, [8]),
    (OE, DISABLE_VOLTAGE, SWD, [9]),
    (SO, DISABLE_VOLTAGE, SWD, [10]),
    (SO, QUICK_STOP, SWD, [10]),
    (OE, QUICK_STOP, QSA, [11]),
    (QSA, DISABLE_VOLTAGE, SWD, [12]),
    (FAULT, 0x80, SWD, [15]),               # fault reset: 0 -> 1 in bit 7
    # commands that are no transition from a state leave it
    (SWD, SWITCH_ON, SWD, []),
    (SWD, ENABLE_OP, SWD, []),
    (QSA, ENABLE_OP, QSA, []),              # quick stop option code 2: no 16
    (FAULT, ENABLE_OP, FAULT, []),
]

net = connect("vcan0")
drive = Drive402(net, 5)

bad = []
for frm, cw, to, trans in TABLE:
    drive.reset_drive()
    drive.st = frm
    drive.pcw = 0                           # the previous controlword: bit 7 low
    drive.trans = []
    drive.command(cw)
    if drive.st != to or drive.trans != trans:
        bad.append(f"{frm} --{cw:#04x}--> {drive.st} {drive.trans}, expected {to} {trans}")
report("table_transitions", not bad, "; ".join(bad) or f"{len(TABLE)} rows")

drive.reset_drive()
drive.st = QSA
drive.set(0x605A, 0, 6)                     # option code 6: 16 allowed
drive.command(ENABLE_OP)
report("table_transition_16_with_option_code_6", drive.st == OE and drive.trans == [16], f"{drive.st} {drive.trans}")
drive.set(0x605A, 0, 2)

bad = []
for st, (mask, val) in PATTERN.items():
    drive.reset_drive()
    drive.st = st
    drive._publish()
    sw = drive.get(0x6041)
    if sw & mask != val:
        bad.append(f"state {st}: statusword {sw:#06x}")
drive.reset_drive()
drive.fault(0x2310)
report("statusword_patterns_and_fault_13_14", not bad and drive.trans == [13, 14] and drive.st == FAULT
       and drive.get(0x603F) == 0x2310, "; ".join(bad) or f"fault: {drive.trans}")

# ---- python-canopen's BaseNode402 as the master, over the bus ----
drive.reset_drive()
mnet = connect("vcan0")
master = canopen.BaseNode402(5, build_od402(5))
mnet.add_node(master)
master.nmt.state = "OPERATIONAL"
ok = wait_for(lambda: drive.state == 5, 2)
mnet.sync.start(0.01)
steps = []


def step(name, action, cond, expect):
    drive.trans = []
    try:
        action()
        err = ""
    except Exception as e:          # BaseNode402 raises on a refused or timed-out change
        err = f" ({type(e).__name__}: {e})"
    ok = wait_for(cond, 2)
    report(f"basenode402_{name}", ok and drive.trans == expect and not err,
           f"drive in {drive.state_name}, transitions {drive.trans}, expected {expect}{err}")


def set_state(s):
    return lambda: setattr(master, "state", s)


step("power_up", set_state("OPERATION ENABLED"), lambda: master.state == "OPERATION ENABLED", [2, 3, 4])
step("quick_stop", set_state("QUICK STOP ACTIVE"), lambda: master.state == "QUICK STOP ACTIVE", [11])
step("disable_voltage", set_state("SWITCH ON DISABLED"), lambda: master.state == "SWITCH ON DISABLED", [12])
step("up_again", set_state("OPERATION ENABLED"), lambda: drive.st == OE, [2, 3, 4])
drive.trans = []
drive.fault(0x8611)
report("basenode402_sees_the_fault", wait_for(master.is_faulted, 2), f"statusword {master.statusword:#06x}")
step("reset_from_fault", master.reset_from_fault, lambda: master.state == "OPERATION ENABLED", [15, 2, 3, 4])
report("basenode402_reads_0x603F", master.sdo[0x603F].raw == 0, f"{master.sdo[0x603F].raw:#06x}")


def mode_csp():
    master.op_mode = "CYCLIC SYNCHRONOUS POSITION"


step("mode_display_follows_csp", mode_csp, lambda: master.op_mode == "CYCLIC SYNCHRONOUS POSITION", [])
drive.home_at = 1234
try:
    homed = master.homing(timeout=3)
except Exception as e:
    homed = f"{type(e).__name__}: {e}"
report("basenode402_homing", homed is True and drive.get(0x6064) == 1234 and drive.get(0x6061) == 6,
       f"homing() {homed}, position {drive.get(0x6064)}, mode display {drive.get(0x6061)}")
mnet.sync.stop()
mnet.disconnect()
net.disconnect()
sys.exit(0 if report.all_passed() else 1)
