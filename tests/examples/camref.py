"""Independent references for the CAM example tests: the seed's curves as
scipy clamped cubic splines (docs/cam.md: each run of C segments a spline,
T segments straight, both cycle ends at the mean of the natural spline's end
slopes, ENDTYPE 0), and the samples' bookkeeping."""
import numpy as np
from scipy.interpolate import CubicSpline


class Curve:
    """fix: [(master, slave, tangent)], one cycle; evaluated modulo the cycle
    with the slave's rise per cycle added."""

    def __init__(self, fix):
        self.m = np.array([f[0] for f in fix], float)
        self.s = np.array([f[1] for f in fix], float)
        self.t = [f[2] for f in fix]
        self.cycle = self.m[-1] - self.m[0]
        self.rise = self.s[-1] - self.s[0]
        n = len(fix)
        # runs: maximal sequences of C segments between T segments
        seg_t = [self.t[i] for i in range(n - 1)]
        runs, i = [], 0
        while i < n - 1:
            if seg_t[i]:
                i += 1
                continue
            j = i
            while j < n - 1 and not seg_t[j]:
                j += 1
            runs.append((i, j))          # points i..j
            i = j
        tslope = {i: (self.s[i + 1] - self.s[i]) / (self.m[i + 1] - self.m[i]) for i in range(n - 1) if seg_t[i]}

        def slope_at(k, side):
            # the T slope fixed at point k (from the segment before or after), if any
            if side == "left" and k - 1 in tslope:
                return tslope[k - 1]
            if side == "right" and k in tslope:
                return tslope[k]
            return None

        if seg_t[0] or seg_t[-1]:
            vend = tslope.get(0, tslope.get(n - 2))
        else:
            a0, a1 = runs[0]
            r = slope_at(a1, "right")
            sp = CubicSpline(self.m[a0:a1 + 1], self.s[a0:a1 + 1],
                             bc_type=((2, 0.0), (1, r) if r is not None else (2, 0.0)))
            va = sp(self.m[0], 1)
            b0, b1 = runs[-1]
            lft = slope_at(b0, "left")
            sp = CubicSpline(self.m[b0:b1 + 1], self.s[b0:b1 + 1],
                             bc_type=((1, lft) if lft is not None else (2, 0.0), (2, 0.0)))
            vb = sp(self.m[-1], 1)
            vend = (va + vb) / 2
        self.pieces = []
        for a, b in runs:
            lft = vend if a == 0 else slope_at(a, "left")
            rgt = vend if b == n - 1 else slope_at(b, "right")
            self.pieces.append((self.m[a], self.m[b], CubicSpline(self.m[a:b + 1], self.s[a:b + 1],
                                                                  bc_type=((1, lft), (1, rgt)))))
        self.lines = [(self.m[i], self.m[i + 1], self.s[i], tslope[i]) for i in tslope]

    def __call__(self, mpos):
        """slave position at master position mpos within the cycle"""
        x = self.m[0] + (mpos - self.m[0]) % self.cycle
        for a, b, sl, k in self.lines:
            if a <= x <= b:
                return sl + (x - a) * k
        for a, b, sp in self.pieces:
            if a <= x <= b:
                return float(sp(x))
        raise ValueError(x)

    def mod_rise(self, s, ref):
        """s moved by whole rises to be nearest ref"""
        return s + round((ref - s) / self.rise) * self.rise
