#!/usr/bin/env python3
"""Reference vectors for tests/unit/test_multdemod.c (scipy, double precision).

Writes to tests/vectors/:
  multdemod_lp_sos.csv   low-pass of the multiplicative demodulator: 4th-order
                         Butterworth, 100 Hz at 50 kHz, as second-order sections, one
                         row per section: b0, b1, b2, a1, a2 (a0 = 1, scipy's sign
                         convention, which biquad.h uses too)
  multdemod_ref.csv      d, sin, cos, in-phase, quadrature: a test signal of model (5-1)
                         with amplitude steps and noise, and the demodulator outputs
                         computed by scipy.signal.sosfilt on 2 d sin and 2 d cos

The input columns and the coefficients are rounded to float32 before the reference is
computed, so the firmware (single precision) and scipy see exactly the same numbers.

Run: python3 tools/gen_demod_vectors.py
"""
import os

import numpy as np
from scipy import signal

FS_HZ = 50000.0
FC_HZ = 1750.0
N = 3000

here = os.path.dirname(os.path.abspath(__file__))
out = os.path.join(here, "..", "tests", "vectors")

sos = signal.butter(4, 100.0, btype="low", fs=FS_HZ, output="sos")
# The firmware holds the coefficients in float. Rounding them moves this filter's DC gain
# by about 2e-4 (poles within 1e-2 of z = 1), a property of the filter, not of the
# demodulator: the reference uses the same rounded coefficients, so that the test
# measures the demodulator's arithmetic.
sos = sos.astype(np.float32).astype(np.float64)
with open(os.path.join(out, "multdemod_lp_sos.csv"), "w") as f:
    f.write("# 4th-order Butterworth low-pass, 100 Hz, fs 50 kHz (tools/gen_demod_vectors.py)\n")
    f.write("# b0, b1, b2, a1, a2 per section (a0 = 1)\n")
    for row in sos:
        f.write(", ".join("%.17g" % v for v in (row[0], row[1], row[2], row[4], row[5])) + "\n")

rng = np.random.default_rng(20030901)
k = np.arange(N)
s = np.sin(2 * np.pi * FC_HZ / FS_HZ * k).astype(np.float32)
c = np.cos(2 * np.pi * FC_HZ / FS_HZ * k).astype(np.float32)
a1 = np.where(k < N // 2, 0.01, -0.005)
a2 = np.where(k < N // 3, 0.0, 0.004)
d = (a1 * s + a2 * c + 0.002 * rng.standard_normal(N)).astype(np.float32)
d64, s64, c64 = d.astype(np.float64), s.astype(np.float64), c.astype(np.float64)
i_ref = signal.sosfilt(sos, 2.0 * d64 * s64)
q_ref = signal.sosfilt(sos, 2.0 * d64 * c64)
with open(os.path.join(out, "multdemod_ref.csv"), "w") as f:
    f.write("# multiplicative demodulator reference (tools/gen_demod_vectors.py)\n")
    f.write("# d, sin, cos, in_phase, quadrature\n")
    for row in zip(d64, s64, c64, i_ref, q_ref):
        f.write("%.9g, %.9g, %.9g, %.12g, %.12g\n" % row)
