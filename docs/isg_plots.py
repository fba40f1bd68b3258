#!/usr/bin/env python3
"""Plots of docs/isg.md ("Both stages") from the rows docs/isg_plots.sh
dumped: the seed's two-mode axis (53 Hz and 11 Hz modes) without damping
and with both ISGDAMP stages.

    isg_plots.py ROWS.txt OUTDIR
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

G = 1e-6  # counts/s^2 -> 10^6 counts/s^2 on the axes


def main():
    rows = np.array([list(map(float, l.split()[1:8])) for l in open(sys.argv[1]) if l.startswith("ROW ")])
    t, off, on, vadd, vset, eoff, eon = rows.T
    out = sys.argv[2]

    # 1. the forward move: ramps, the 53 Hz shaker while driving, the stop
    fig, ax = plt.subplots(3, 1, figsize=(10, 8), sharex=True)
    m = t < 4.0
    ax[0].plot(t[m], vset[m] / 1000, color="k")
    ax[0].set_ylabel("setpoint speed\n(1000 counts/s)")
    ax[0].set_title("The seed's two-mode axis, forward move: load acceleration without and with ISGDAMP")
    ax[1].plot(t[m], off[m] * G, lw=0.6, label="without damping")
    ax[1].plot(t[m], on[m] * G, lw=0.6, label="53 Hz DIRECT + 11 Hz INDIRECT")
    ax[1].set_ylabel("load acceleration\n(10^6 counts/s^2)")
    ax[1].legend(loc="upper right")
    ax[1].axvspan(0.6, 2.1, color="0.9", zorder=0)
    ax[1].text(0.62, ax[1].get_ylim()[1] * 0.8, "53 Hz force on the load", fontsize=8)
    ax[2].plot(t[m], vadd[m] / 1000, lw=0.6, color="C1")
    ax[2].set_ylabel("v_add\n(1000 counts/s)")
    ax[2].set_xlabel("time (s)")
    fig.tight_layout()
    fig.savefig(f"{out}/isg-seed-move.png", dpi=90)

    # 2. zooms: 53 Hz at constant speed; 11 Hz after braking
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    m = (t >= 1.5) & (t < 1.6)
    ax[0].plot(t[m], off[m] * G, label="without")
    ax[0].plot(t[m], on[m] * G, label="with")
    ax[0].set_title("53 Hz while driving (DIRECT, Q 10)")
    ax[0].set_xlabel("time (s)")
    ax[0].set_ylabel("load acceleration (10^6 counts/s^2)")
    ax[0].legend(loc="upper right")
    m = (t >= 2.8) & (t < 3.5)
    ax[1].plot(t[m], off[m] * G, label="without")
    ax[1].plot(t[m], on[m] * G, label="with")
    ax[1].axvspan(2.8, 2.9, color="0.9", zorder=0)
    ax[1].set_title("11 Hz after braking (INDIRECT, damping 0.5)")
    ax[1].set_xlabel("time (s); grey: the braking ramp")
    ax[1].legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(f"{out}/isg-seed-zoom.png", dpi=90)

    # 3. the position gain: a setpoint step at Kv 25 1/s on the fast drive
    fig, ax = plt.subplots(figsize=(10, 3.5))
    m = t < 2.0
    ax.plot(t[m], eoff[m], lw=0.8, label="without damping (stable up to Kv 18)")
    ax.plot(t[m], eon[m], lw=0.8, label="DIRECT 53 Hz, Q 2, 20/200 (stable up to Kv 33)")
    ax.set_ylim(-1100, 1100)
    ax.set_title("1000-count setpoint step at Kv 25 1/s: 2 ms drive, loop on the load encoder, 53 Hz at zeta 0.02")
    ax.set_xlabel("time after the step (s)")
    ax.set_ylabel("following error (counts)")
    ax.legend(loc="lower right")
    fig.tight_layout()
    fig.savefig(f"{out}/isg-gain-step.png", dpi=90)


if __name__ == "__main__":
    main()
