"""Seed 000's ENCODERTYPE 50 on a real bus (vcan0 inside a kernel with CAN,
tests/canopen/bus_run.sh): plcrt runs st/canopen_enc.st, an APOSSAXIS whose
loop is closed through a CiA 406 encoder, node 5 (enc406.Encoder406: its
position value 0x6004 in TPDO2 on SYNC), and whose speed reference goes to
analog output 1 of CiA 401 node 4 (slave401.Slave401, DRIVETYPE 91): the
encoder sits on the shaft of the motor that output drives.  Both nodes are
guarded.  The encoder starts 6000 counts below 2^31 and a POSA carries it
across; then it stops answering guarding during a move: error 88 and the
reference 0 on the bus within guard time x life factor / cycle + 2 RPDOs
of its last answer (the recorded frames, with their kernel timestamps
reported); ERRCLR while it is silent
raises 88 again; a negative ENCODERTYPE lets ERRCLR stand; a wrong id is
refused (parerr 27, AP held); answering again, AP is the encoder's value
and the axis moves; as device type 1 (incremental) a reset of the node with
its count elsewhere moves AP by nothing.  Bad configurations first.

    $PY tests/canopen/plcrt_encodertype_test.py PLCRT OUT_DIR
"""
import os
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from apossmb import AxisMb  # noqa: E402
from slave401 import CanDump, Slave401, connect, reference_zero_after  # noqa: E402
from enc406 import Encoder406  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from peer import Report, wait_for  # noqa: E402

plcrt, out = sys.argv[1], sys.argv[2]
PORT = 15036
# both nodes guarded every 100 ms and lost after 10 missed answers: this
# test process, stalled by a loaded host, must not look like a silent node
GUARD, LIFE, CYCLE = 0.100, 10, 0.010
TESTWIN = 50
POSERR = 20000
VMAX = 40000.0                  # qc/s at 10 V: the motor model's, VELMAX 600 rpm x ENCODER 1000 x 4
START = 2**31 - 6000            # the encoder's first value, unsigned 32 bit
report = Report("canopen_encodertype")

MODULE4 = """[canopen.module4]
id = 4
device_type = 0x191
drivetype = 91
life_factor = 10
rpdo1 = 0x6411:01:16 0x6411:02:16 0x6411:03:16 0x6411:04:16
bind = 0x6411:01 %QW0
bind = 0x6411:02 %QW1
bind = 0x6411:03 %QW2
bind = 0x6411:04 %QW3
status = %IW30
"""


def config(name, enc_keys, port=PORT):
    path = os.path.join(out, name)
    with open(path, "w") as f:
        f.write(f"""[plc]
log_level = info
[io]
backend = canopen
[modbus]
port = {port}
[canopen]
interface = vcan0
cansynctimer_ms = 10
{MODULE4}
[canopen.enc5]
id = 5
device_type = 0x10196
life_factor = {LIFE}
{enc_keys}
status = %IW31
""")
    return path


# ---- bad configurations: plcrt refuses to start, naming section and key ----
for name, keys, want in (
        ("wrong_id", "encodertype = 50006\nbind = 0x6004:00 %ID0", ["[canopen.enc5]", "encodertype 50006", "encodertype = 50005"]),
        ("bad_form", "encodertype = 60005\nbind = 0x6004:00 %ID0", ["bad_form.ini:", "[canopen.enc5] encodertype", "60005", "device type 1..50"]),
        ("no_bind", "encodertype = 50005", ["[canopen.enc5]", "encodertype 50005", "bind = 0x6004:00"])):
    r = subprocess.run([plcrt, "-c", config(f"bad_{name}.ini", keys, PORT + 1)],
                       capture_output=True, text=True, timeout=20)
    msg = (r.stdout + r.stderr).strip()
    report(f"config_{name}_refused", r.returncode == 2 and all(w in msg for w in want),
           f"status {r.returncode}: {msg[-300:]}")

cfg = config("encodertype.ini", "encodertype = 50005\nbind = 0x6004:00 %ID0")
trace = CanDump(os.path.join(out, "candump.log"))
net = connect("vcan0")
module = Slave401(net, 4)
enc = Encoder406(net, 5, module, pos=START, maxvel=VMAX)
log = open(os.path.join(out, "plcrt.log"), "w")
plc = subprocess.Popen([plcrt, "-c", cfg], stdout=log, stderr=subprocess.STDOUT)
mb = AxisMb(PORT)
ok = wait_for(lambda: mb.connect(), 10) and wait_for(lambda: module.state == 5 and enc.state == 5, 5)
mw, mds, md, put_md, command, bits, errnum = mb.mw, mb.mds, mb.md, mb.put_md, mb.command, mb.bits, mb.errnum


def signed(v):
    v %= 2**32
    return v - 2**32 if v >= 2**31 else v


def after_cycles(n):
    """wait until the PLC has run n more cycles (its own counter)"""
    c0 = md(6)
    return c0 is not None and wait_for(lambda: (md(6) or c0) - c0 >= n, 10)


def move(c, pos, seen=None):
    """a POSA/POSR, to its end: APOS in the cycle in which INPOS rose (the
    program latches it), or None; the (APOS, AP) of every cycle read on the
    way go to seen"""
    n0 = md(9)
    command(c, pos)

    def ended():
        r = mds(2, 8)
        if r and seen is not None:
            seen.append(r[:2])
        return r and r[7] != n0 and not r[5] & BUSY
    return md(8) if n0 is not None and wait_for(ended, 15) else None


def at_rest():
    """motor off (reference 0): the encoder stands; AP settled on its value"""
    command(2)
    return wait_for(lambda: not bits() & MOTOR, 5) and after_cycles(5)


def ap_window():
    """AP as docs/drives.md defines it for a CiA 406 encoder whose first
    value lay beyond 2^30: the value - 2^31, taken modulo 2^32"""
    return signed(enc.value - 2**31)


MOTOR, BUSY, INPOS, ERROR, ENCERR, OUTERR = 1, 2, 4, 8, 16, 32
rtr0 = enc.guard_rtrs
ok = ok and wait_for(lambda: md(3) == ap_window(), 5)
report("ap_is_encoder_value_in_window", ok and md(3) == -6000 and md(2) == -6000,
       f"encoder {enc.value}, AP {md(3)}, APOS {md(2)}")
wait_for(lambda: enc.guard_rtrs - rtr0 >= 3, 2)
report("guarded_tpdo2_maps_0x6004",
       enc.get(0x100C) == 100 and enc.get(0x100D) == LIFE and enc.guard_rtrs - rtr0 >= 3
       and enc._u32(0x1A01, 0) == 1 and enc._u32(0x1A01, 1) == 0x60040020 and enc._u32(0x1801, 2) == 1
       and enc._u32(0x1800, 1) & 0x80000000,
       f"0x100C {enc.get(0x100C)} ms, 0x100D {enc.get(0x100D)}, {enc.guard_rtrs - rtr0} RTRs; "
       f"0x1A01 {enc._u32(0x1A01, 0)} x {enc._u32(0x1A01, 1):#x}, type {enc._u32(0x1801, 2)}, "
       f"TPDO1 COB-ID {enc._u32(0x1800, 1):#x}")

# across 2^31: the encoder's value goes from 2^31 - 6000 to 2^31 + 6000
command(1)
wait_for(lambda: bits() & MOTOR, 5)
seen = []
r = move(4, 6000, seen)
# no sample beyond the span by more than POSERR (error 8 would stop it): a
# wrap of AP would put one 2^31 or 2^32 away; samples on both sides of the
# encoder's seam (AP 0 = 2^31)
wild = [s[:2] for s in seen if not -6000 - POSERR <= s[0] <= 6000 + POSERR or s[0] != s[1]]
sides = any(s[0] < -1000 for s in seen) and any(s[0] > 1000 for s in seen)
report("posa_across_2_31_ends_in_testwin", r is not None and abs(r - 6000) <= TESTWIN and errnum() == 0,
       f"APOS {r} in the cycle INPOS rose, ERRNUM {errnum()}")
report("ap_continuous_across_the_seam", sides and not wild,
       f"{len(seen)} (APOS, AP) samples during the move, on both sides of 2^31, none off the span"
       + (f"; outside: {wild[:3]}" if wild else ""))
ok = at_rest() and wait_for(lambda: md(3) == ap_window(), 5)
report("ap_is_encoder_value_after_the_seam", ok, f"AP {md(3)}, encoder - 2^31 {ap_window()}")
command(1)
wait_for(lambda: bits() & MOTOR, 5)

# a long move, and the encoder falls silent in the middle of it
command(4, -200000)
running = wait_for(lambda: abs(module.get(0x6411, 1)) > 3000, 5)
t_silent = time.time()                              # the bus trace's clock
enc.guard_answer = False
ok = wait_for(lambda: errnum() == 88, 5)
b = bits()
report("silent_encoder_error_88_loop_open", ok and not b & MOTOR and b & ENCERR and not b & OUTERR,
       f"ERRNUM {errnum()}, bits {b}")
n88 = md(4)
command(3)                                          # ERRCLR while still silent
ok = wait_for(lambda: md(4) == n88 + 1, 5)
report("errclr_while_silent_raises_88_again", ok and errnum() == 88, f"errors 88: {n88} -> {md(4)}")
put_md(5, -50005)                                   # the seed's way out: no guarding
after_cycles(2)
n88 = md(4)
command(3)
ok = wait_for(lambda: errnum() == 0, 5) and after_cycles(30)
report("negative_encodertype_errclr_stands", ok and errnum() == 0 and md(4) == n88 and not bits() & ERROR,
       f"ERRNUM {errnum()} 30 cycles after ERRCLR, errors 88 {n88} -> {md(4)}")
put_md(5, 50005)
report("positive_again_88_again", wait_for(lambda: errnum() == 88, 5), f"ERRNUM {errnum()}")

enc.guard_answer = True
ok = wait_for(lambda: not bits() & ENCERR, 10) and wait_for(lambda: md(3) == ap_window(), 5)
command(3)
ok = ok and wait_for(lambda: errnum() == 0, 5)
report("answers_again_ap_is_encoder_value", ok and errnum() == 0 and md(3) == ap_window(),
       f"ERRNUM {errnum()}, AP {md(3)}, encoder - 2^31 {ap_window()}")

# a wrong id: refused, AP held while the encoder turns
put_md(5, 50006)
ok = wait_for(lambda: (mw(4) or [0])[0] == 27, 5) and wait_for(lambda: errnum() == 88, 5)
ap0 = md(3)
enc.turn(1000)                                      # turned by hand
after_cycles(20)
report("wrong_id_parerr_27_ap_held", ok and md(3) == ap0 and bits() & ENCERR,
       f"parerr {mw(4)}, ERRNUM {errnum()}, AP {ap0} -> {md(3)} (encoder +1000)")
put_md(5, 50005)
ok = wait_for(lambda: md(3) == ap_window(), 5)
command(3)
ok = ok and wait_for(lambda: errnum() == 0, 5)
report("right_id_again_absolute", ok and md(3) == ap0 + 1000, f"AP {md(3)}, ERRNUM {errnum()}")
command(1)
wait_for(lambda: bits() & MOTOR, 5)
r = move(4, 0)
ok = at_rest() and wait_for(lambda: md(3) == ap_window(), 5)
report("moves_again", r is not None and abs(r) <= TESTWIN and ok,
       f"APOS {r} in the cycle INPOS rose; at rest AP {md(3)}, encoder - 2^31 {ap_window()}")

# device type 1: incremental; the node resets with its count elsewhere
ra = mds(2, 2)
put_md(5, 1005)
after_cycles(10)
r0 = mds(2, 2)
report("incremental_switch_no_jump", r0 == ra, f"(APOS, AP) {ra} as type 50, {r0} as type 1")
enc.boot()                                          # an unexpected reset: pre-operational ...
enc.turn(1000000)                                   # ... and its count restarts elsewhere
ok = wait_for(lambda: enc.state == 5, 10) and after_cycles(20)
r1 = mds(2, 2)
report("incremental_reset_no_jump", ok and r1 == r0 and errnum() == 0,
       f"(APOS, AP) {r0} -> {r1} across the reset (encoder +1000000)")
e0 = enc.pos
command(1)
wait_for(lambda: bits() & MOTOR, 5)
r = move(5, 5000)
ok = at_rest()
r2 = mds(2, 2)
moved = int(round(enc.pos)) - int(round(e0))
report("incremental_posr_moves_encoder", r is not None and abs(r - r1[0] - 5000) <= TESTWIN and ok
       and abs((r2[0] - r1[0]) - moved) <= 1,
       f"APOS {r1[0]} -> {r} in the cycle INPOS rose; at rest APOS moved {r2[0] - r1[0]}, "
       f"the encoder {moved}; ERRNUM {errnum()}")
plc.send_signal(signal.SIGTERM)
report("plcrt_exits_0", plc.wait(10) == 0)

# ---- on the bus: the encoder's last good answer, then the reference RPDOs ----
answers = [t for t, d in trace.frames(0x705) if d and d[0] & 0x7F == 0x05]
rpdo = trace.frames(0x204)
t_last = max([a for a in answers if a < t_silent], default=None)
if t_last is None:
    report("reference_zero_past_life_time", False, "no guarding answer of the encoder recorded")
else:
    nxt = min([a for a in answers if a > t_last], default=float("inf"))
    ok, why = reference_zero_after(rpdo, t_last, nxt, GUARD * LIFE, CYCLE)
    report("reference_zero_past_life_time", ok and running,
           why + f"; silenced {(t_silent - t_last) * 1000:.0f} ms after that answer")
trace.close(keep=not report.all_passed())
sys.exit(0 if report.all_passed() else 1)
