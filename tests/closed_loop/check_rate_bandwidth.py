#!/usr/bin/env python3
"""Rate bandwidth and group delay of the closed-loop gyro from a sine sweep of the input
rate (issue figures; thesis 5.4.3/7.2.4: 100 Hz output low-pass). For each frequency,
gyro-sim runs the default plant with rate = 10 sin(2 pi f t) deg/s; a least-squares sine
fit at f of the firmware's rate output against the true rate gives gain and phase. The
-3 dB frequency is interpolated on the gain; the group delay is the phase slope at low
frequency. Prints the table; exits 1 if the bandwidth is outside 80..120 Hz (the output
Butterworth is 100 Hz, the sense demodulator's 282 Hz adds a little lag) or the DC gain
is off by more than 1 %. Arguments after the gyro-sim path go to every gyro-sim run (for
instance --set firmware.selftest.continuous=1)."""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np


def fit(t, y, f):
    a = np.column_stack([np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t), np.ones_like(t)])
    c, *_ = np.linalg.lstsq(a, y, rcond=None)
    return c[0] + 1j * c[1]


# The default part's calibration (tools/calibrate): the firmware's defaults are generic.
PART = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "host_sim", "parts",
                    "default", "calibration.json")


def main():
    exe = sys.argv[1]
    extra = sys.argv[2:]
    freqs = [2.0, 5.0, 20.0, 50.0, 80.0, 100.0, 120.0, 150.0]
    rows = []
    with tempfile.TemporaryDirectory() as d:
        for f in freqs:
            scen = os.path.join(d, "s.json")
            json.dump({"name": "rate_sine", "duration_s": 1.0 + 5.0 / f, "seed": 5,
                       "csv_rate_hz": 5000,
                       "rate_dps": {"kind": "sine", "value": 0, "amp": 10, "freq_hz": f}},
                      open(scen, "w"))
            csv = os.path.join(d, "t.csv")
            subprocess.run([exe, "--scenario", scen, "--firmware-params", PART, "--quiet",
                            "--no-analysis", "--csv", csv] + extra, check=True)
            t = np.genfromtxt(csv, delimiter=",", names=True)
            m = t["t_s"] >= 0.5
            h = fit(t["t_s"][m], t["rate_dps"][m], f) / fit(t["t_s"][m], t["rate_true_dps"][m], f)
            rows.append((f, abs(h), np.degrees(np.angle(h))))
    print(" f [Hz]   gain    phase [deg]")
    for f, g, p in rows:
        print(f"{f:7.1f}  {g:.4f}  {p:9.2f}")
    fr = np.array([r[0] for r in rows])
    g = np.array([r[1] for r in rows])
    ph = np.unwrap(np.radians([r[2] for r in rows]))
    g0 = g[0]
    i = int(np.argmax(g < g0 / np.sqrt(2)))
    bw = np.interp(g0 / np.sqrt(2), [g[i], g[i - 1]], [fr[i], fr[i - 1]]) if i > 0 else float("nan")
    gd = -(ph[1] - ph[0]) / (2 * np.pi * (fr[1] - fr[0]))
    print(f"-3 dB bandwidth {bw:.1f} Hz, group delay {1e3 * gd:.2f} ms (from {fr[0]:g}-{fr[1]:g} Hz), DC gain {g0:.4f}")
    return 0 if (80.0 <= bw <= 120.0 and abs(g0 - 1.0) < 0.01) else 1


if __name__ == "__main__":
    sys.exit(main())
