#!/usr/bin/env python3
"""The highest stable position gain, by analysis: the closed-loop
eigenvalues of the sampled linear model of the axis of docs/isg.md ("The
position gain") and tests/isg/t_seedcase.st, independent of the ST code.

  plant     the motor follows its speed reference through a first-order lag
            tau (an ideal speed source); one elastic mode between motor and
            load, d'' + 2 zeta w d' + w^2 d = -a_motor; load = motor + d;
            held over each 1 ms sample (zero-order hold, matrix exponential)
  loop      v = Kv (setpoint - load position), 1 ms, no feed-forward
  stage     DIRECT on the load speed (load position differenced each
            sample): the band-pass of docs/isg.md ("The filters": order n,
            -3 dB band f0/Q centred geometrically on f0, gain 1 at f0, both
            edges pre-warped), times the weight, added to v

The loop is stable when every eigenvalue of the one-sample state map lies
inside the unit circle; the highest stable Kv is found on a grid from 0.5
(steps of 0.5 up to 1000, then of 1 %).  Printed: that Kv and the frequency
of the eigenvalue that leaves the circle there (the oscillation that limits
the gain); last, a stiff load, for what the 1 ms sampling alone allows.

    gain_analysis.py
"""
import numpy as np
from scipy.linalg import expm

TS = 0.001


def plant_map(tau, hz, zeta):
    """x[k+1] = A x[k] + B v[k], x = (v_motor, x_motor, d, d'); load = x_motor + d."""
    w = 2 * np.pi * hz
    a = np.array([[-1 / tau, 0, 0, 0],
                  [1, 0, 0, 0],
                  [0, 0, 0, 1],
                  [1 / tau, 0, -w * w, -2 * zeta * w]])
    b = np.array([1 / tau, 0, 0, -1 / tau])
    m = np.zeros((5, 5))
    m[:4, :4] = a
    m[:4, 4] = b
    e = expm(m * TS)
    return e[:4, :4], e[:4, 4]


def bandpass(f0, q, n):
    """One second-order section b0 (1 - z^-2) / (1 + a1 z^-1 + a2 z^-2) of the
    n-section cascade specified in docs/isg.md."""
    cfac = 2 ** (1 / n)
    r = 0.5 / q
    fh = f0 * (r + np.sqrt(1 + r * r))
    fl = f0 * f0 / fh
    k = 2 / TS
    wl, wh, wf = (k * np.tan(np.pi * f * TS) for f in (fl, fh, f0))
    w0 = np.sqrt(wl * wh)
    uh, u0 = wh / w0 - w0 / wh, wf / w0 - w0 / wf
    qs = np.sqrt((cfac - 1) / (uh * uh - cfac * u0 * u0))
    aa = w0 / qs
    den = k * k + aa * k + w0 * w0
    b0, a1, a2 = aa * k / den, 2 * (w0 * w0 - k * k) / den, (k * k - aa * k + w0 * w0) / den
    z = np.exp(1j * 2 * np.pi * f0 * TS)
    g = abs(b0 * (1 - z ** -2) / (1 + a1 / z + a2 / z ** 2))
    return b0 / g, a1, a2


def closed_loop(kv, tau, hz, zeta, stage):
    """The one-sample map of (plant, previous load position, speed command,
    band-pass sections' states) for gain kv; stage = (f0, Q, order, weight)
    or None."""
    a, b = plant_map(tau, hz, zeta)
    nsec = stage[2] if stage else 0
    sec = bandpass(*stage[:3]) if stage else None
    n = 4 + 2 + 2 * nsec

    def step(s):
        x, prev, v = s[:4], s[4], s[5]
        x = a @ x + b * v
        load = x[1] + x[2]
        vl = (load - prev) / TS
        u = kv * (0.0 - load)
        out = np.zeros(n)
        if stage:
            b0, a1, a2 = sec
            y = vl
            for i in range(nsec):
                s1, s2 = s[6 + 2 * i], s[7 + 2 * i]
                o = b0 * y + s1
                out[6 + 2 * i] = s2 - a1 * o
                out[7 + 2 * i] = -b0 * y - a2 * o
                y = o
            u += stage[3] * y
        out[:4], out[4], out[5] = x, load, u
        return out

    return np.column_stack([step(np.eye(n)[j]) for j in range(n)])


def highest(tau, hz, zeta, stage, kvmax=5000):
    kv, last = 0.5, None
    while kv <= kvmax:
        ev = np.linalg.eigvals(closed_loop(kv, tau, hz, zeta, stage))
        i = np.argmax(abs(ev))
        if abs(ev[i]) >= 1:
            return last, abs(np.angle(ev[i])) / (2 * np.pi * TS)
        last = kv
        kv += 0.5 if kv < 1000 else 0.01 * kv     # 0.5 up to 1000, then 1 %
    return last, float("nan")


def main():
    cases = [
        ("2 ms drive, damping off", 0.002, None),
        ("2 ms drive, DIRECT Q 2 20/200", 0.002, (53.0, 2.0, 2, 0.1)),
        ("2 ms drive, DIRECT Q 1 40/200", 0.002, (53.0, 1.0, 2, 0.2)),
        ("2 ms drive, DIRECT Q 10 10/200", 0.002, (53.0, 10.0, 2, 0.05)),
        ("20 ms drive, damping off", 0.02, None),
        ("20 ms drive, DIRECT Q 10 100/200", 0.02, (53.0, 10.0, 2, 0.5)),
    ]
    for name, tau, stage in cases:
        kv, f = highest(tau, 53.0, 0.02, stage)
        print(f"  {name}: highest stable Kv {kv:g} 1/s, then unstable at {f:.1f} Hz")
    # a stiff load (its mode at 1000 Hz, well damped): what the sampling allows
    kv, f = highest(0.02, 1000.0, 0.7, None)
    print(f"  20 ms drive, stiff load (mode at 1000 Hz, zeta 0.7): highest stable Kv {kv:g} 1/s, then unstable at {f:.1f} Hz")


if __name__ == "__main__":
    main()
