"""CiA 402 axes per CAN bus: the frames one drive needs per SYNC period with
the example's PDO mapping (read from its DCF by python-canopen, not by our
reader), each frame at its worst-case length with bit stuffing (11-bit
identifier: 47 + 8n bits, of which the 34 + 8n before the CRC delimiter
may gain a stuff bit every 4), against the bit time at 1 Mbit/s.

    python3 bench/cia402/busload.py examples/cia402/drive402.eds
"""
import sys

import canopen

BITRATE = 1_000_000


def frame_bits(n):
    """worst-case bits of a standard data frame with n data bytes, plus the
    3-bit interframe space"""
    return 47 + 8 * n + (34 + 8 * n - 1) // 4 + 3


od = canopen.import_od(sys.argv[1], 5)
sizes = []
for base in (0x1600, 0x1A00):
    for k in range(4):
        if base + k not in od:
            continue
        m = od[base + k]
        cnt = int(m[0].value if m[0].value is not None else m[0].default)
        bits = sum(int(m[s].value if m[s].value is not None else m[s].default) & 0xFF for s in range(1, cnt + 1))
        if cnt:
            sizes.append((("RPDO" if base == 0x1600 else "TPDO") + str(k + 1), (bits + 7) // 8))
per_axis = sum(frame_bits(n) for _, n in sizes)
sync = frame_bits(0)
print("bench-cia402: frames per drive and SYNC period: " + ", ".join(f"{p} {n} bytes ({frame_bits(n)} bits)"
                                                          for p, n in sizes)
      + f": {per_axis} bits worst case; SYNC {sync} bits")
for period_ms in (1, 4):
    budget = BITRATE * period_ms / 1000
    axes = int((budget - sync) // per_axis)
    print(f"bench-cia402: {period_ms} ms SYNC at 1 Mbit/s: {budget:.0f} bit times, at most {axes} drives "
          f"({(sync + axes * per_axis) / budget * 100:.1f} % bus load; frame-time bound, no other traffic)")
# the minimum a drive needs (docs/drives.md): RPDO1 and TPDO1 only
minimum = sum(frame_bits(n) for p, n in sizes if p in ("RPDO1", "TPDO1"))
for period_ms in (1, 4):
    budget = BITRATE * period_ms / 1000
    axes = int((budget - sync) // minimum)
    print(f"bench-cia402: {period_ms} ms SYNC, RPDO1 and TPDO1 only ({minimum} bits per drive): at most {axes} drives "
          f"({(sync + axes * minimum) / budget * 100:.1f} % bus load)")
