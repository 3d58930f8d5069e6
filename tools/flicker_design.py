#!/usr/bin/env python3
"""Pole/zero layout of the plant's 1/f (flicker) + white noise shaping filter
(host_sim/plant/flicker.c). Prints the constants the C code uses and checks them.

Target one-sided PSD, normalised to the corner fc where 1/f meets white:
    S(f) / W^2 = 1 + fc / f          (W: white density)
Filter: |H(f)|^2 = prod_i (1 + (f/z_i)^2) / (1 + (f/p_i)^2), driven by unit white noise.
Between the corner and the lowest pole, interleaved poles and zeros one per decade give
the -10 dB/decade slope; the top two zero/pole pairs (free positions, relative to fc)
shape the knee, because one first-order zero alone is too sharp for 1 + fc/f (it
leaves a 1.2 dB dip at the corner). The free positions minimise the peak dB error over
four decades either side of fc (differential evolution).

Usage: python3 flicker_design.py   (scipy, numpy)
"""
import numpy as np
from scipy.optimize import differential_evolution

NFREE = 2           # free zero/pole pairs at the knee
PER_DECADE = 1      # regular pairs per decade below the knee


def layout(x, fmin_rel):
    zs = list(10.0 ** np.asarray(x[:NFREE]))
    ps = list(10.0 ** np.asarray(x[NFREE:]))
    r = 10.0 ** (1.0 / PER_DECADE)
    z = min(ps) / np.sqrt(r)
    while True:
        p = z / np.sqrt(r)
        zs.append(z)
        ps.append(p)
        if p <= fmin_rel:
            break
        z /= r
    return np.array(zs), np.array(ps)


def mag2(f, zs, ps):
    h = np.ones_like(f)
    for z, p in zip(zs, ps):
        h *= (1 + (f / z) ** 2) / (1 + (f / p) ** 2)
    return h


def main():
    f = np.logspace(-4, 4, 1200)
    tgt = 1 + 1 / f

    def cost(x):
        zs, ps = layout(x, 1e-6)
        e = 10 * np.log10(mag2(f, zs, ps) / tgt)
        return (e.max() - e.min()) / 2

    res = differential_evolution(cost, [(-3, 1)] * (2 * NFREE), seed=1, tol=1e-10,
                                 maxiter=3000, popsize=40, polish=True)
    x = res.x
    print("peak error +-%.3f dB" % res.fun)
    print("zeros log10(z/fc):", ", ".join("%.8f" % v for v in x[:NFREE]))
    print("poles log10(p/fc):", ", ".join("%.8f" % v for v in x[NFREE:]))
    print("regular part: z = min(pole) * 10^-(k + 1/2), p = z * 10^-1/2, k = 0, 1, ...")


if __name__ == "__main__":
    main()
