#!/usr/bin/env python3
"""The plot of docs/plcopen.md ("Buffer modes and blending") from the rows
docs/plcopen_blend.sh dumped: set-point speed and position of the three
moves with mcBuffered, mcBlendingLow and mcBlendingHigh, the blend points
marked with the velocity PLCopen gives them.

    plcopen_blend.py ROWS.txt OUT.png
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main():
    rows = np.array([list(map(float, l.split()[1:8])) for l in open(sys.argv[1]) if l.startswith("ROW ")])
    t, p1, v1, p2, v2, p3, v3 = rows.T
    fig, ax = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    runs = [(p1, v1, "mcBuffered", "0.5"), (p2, v2, "mcBlendingLow", "tab:blue"),
            (p3, v3, "mcBlendingHigh", "tab:red")]
    for p, v, name, col in runs:
        ax[0].plot(t, v / 1000, color=col, label=name)
        ax[1].plot(t, p / 1000, color=col, label=name)
        for target in (20000.0, 40000.0):
            k = np.argmax(p >= target)
            if p[k] >= target:
                ax[0].plot(t[k], v[k] / 1000, "o", color=col, ms=5)
    ax[0].set_ylabel("set-point speed (1000 Um/s)")
    ax[0].set_title("Three MC_MoveAbsolute (20000 at 10000, 40000 at 20000, 50000 at 5000 Um/s) on EPICPOS;\n"
                    "dots: the speed where the set-point passes 20000 and 40000 "
                    "(Low: min(v1, v2) = 10000, 5000; High: max = 20000, 20000)", fontsize=9)
    ax[0].legend(loc="upper right")
    ax[0].grid(True, lw=0.3)
    ax[1].set_ylabel("set-point (1000 Um)")
    ax[1].set_xlabel("time (s)")
    for y in (20, 40, 50):
        ax[1].axhline(y, color="k", lw=0.3)
    ax[1].grid(True, lw=0.3)
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=90)


if __name__ == "__main__":
    main()
