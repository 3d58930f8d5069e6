#!/usr/bin/env python3
"""Scale factor and its nonlinearity over +-300 deg/s, and their change over -40..85 degC,
force rebalance against open loop (issue 19 item 4), on the part of
tests/closed_loop/test_cl_sense_fr.c (sense Q 1e4 at 1600 Hz, a 110 Hz split, the
half-frequency feedback pair, its model as check_rate_bandwidth.py --fr sets it).

    check_fr_linearity.py GYRO_SIM [--out DIR]

For each mode and each ambient (-40, 25, 85 degC; the structure's and the circuit's
thermal time constants cut to 20 s, 150 s to settle) a rate table 0, +-50 .. +-300 deg/s,
each level held (force rebalance 2 s, open loop 12 s: the open loop rings at the split
for seconds at this Q) and its mean taken over the second half. The figures are of the
uncompensated rate (rate_unc_dps: the intrinsic scale factor, before the default part's
temperature compensation, which was fitted on another part): the slope of a line through
the means (deg/s per deg/s), the nonlinearity as the largest and the RMS residual over
full scale (300 deg/s). Open loop the 1500 deg/s quadrature is removed from the plant
(it would clip the ADC on this part: test_cl_sense_fr.c). Prints the table; with --out,
JSON and a plot. Exit 0, or 2 on a run error: a measurement, not a pass/fail check.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_rate_bandwidth import PART, fr_args  # noqa: E402

LEVELS = [0.0] + [s * r for r in (50, 100, 150, 200, 250, 300) for s in (1, -1)] + [0.0]
FS_DPS = 300.0
SETTLE_S = 150.0
THERMAL = ["--set", "plant.tau_struct_s=20", "--set", "plant.tau_circuit_s=20"]
DWELL_S = {"force rebalance": 2.0, "open loop": 12.0}


def mode_args(exe, mode):
    args = fr_args(exe)
    if mode == "open loop":
        args = [a.replace("firmware.sense.mode=1", "firmware.sense.mode=0")
                .replace("firmware.cal.ref_sense_mode=1", "firmware.cal.ref_sense_mode=0")
                for a in args]
        args += ["--set", "plant.quad_dps=0"]
    return args + THERMAL


def run(exe, mode, amb_c, d):
    dwell = DWELL_S[mode]
    steps = [[SETTLE_S, 0.0]] + [[dwell, r] for r in LEVELS]
    scen = {"name": "fr_linearity", "description": "rate table at a held ambient",
            "duration_s": SETTLE_S + dwell * len(LEVELS), "seed": 11, "mode": "closed_loop",
            "csv_rate_hz": 200, "ambient_c": {"kind": "const", "value": amb_c},
            "rate_dps": {"kind": "steps", "edge_s": 0.0, "steps": steps}}
    sp = os.path.join(d, "s.json")
    with open(sp, "w") as f:
        json.dump(scen, f)
    csv = os.path.join(d, "t.csv")
    subprocess.run([exe, "--scenario", sp, "--firmware-params", PART, "--quiet",
                    "--no-analysis", "--csv", csv] + mode_args(exe, mode), check=True)
    t = np.genfromtxt(csv, delimiter=",", names=True)
    means = []
    for i in range(len(LEVELS)):
        t0 = SETTLE_S + i * dwell
        m = (t["t_s"] >= t0 + 0.5 * dwell) & (t["t_s"] < t0 + dwell)
        means.append(float(np.mean(t["rate_unc_dps"][m])))
    x, y = np.array(LEVELS), np.array(means)
    k, b = np.polyfit(x, y, 1)
    res = y - (k * x + b)
    return {"scale": float(k), "bias_dps": float(b),
            "nonlin_max_pct_fs": float(100 * np.max(np.abs(res)) / (k * FS_DPS)),
            "nonlin_rms_pct_fs": float(100 * np.sqrt(np.mean(res ** 2)) / (k * FS_DPS)),
            "struct_c": float(np.mean(t["t_struct_c"][t["t_s"] > SETTLE_S])),
            "levels_dps": LEVELS, "means_dps": means}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sim")
    ap.add_argument("--out")
    a = ap.parse_args()
    rows = {}
    with tempfile.TemporaryDirectory() as d:
        for mode in DWELL_S:
            for amb in (-40.0, 25.0, 85.0):
                try:
                    rows[f"{mode} {amb:+.0f}"] = run(a.sim, mode, amb, d)
                except (subprocess.CalledProcessError, OSError, ValueError) as e:
                    print(f"run failed: {e}")
                    return 2
    print("| mode | structure [degC] | scale (uncompensated) | change from 25 degC [ppm] | "
          "nonlinearity max / rms [% FS] |")
    print("| --- | --- | --- | --- | --- |")
    for key, r in rows.items():
        mode = key.rsplit(" ", 1)[0]
        ref = rows[f"{mode} +25"]["scale"]
        print(f"| {mode} | {r['struct_c']:.1f} | {r['scale']:.6f} | "
              f"{1e6 * (r['scale'] / ref - 1):+.0f} | {r['nonlin_max_pct_fs']:.4f} / "
              f"{r['nonlin_rms_pct_fs']:.4f} |")
    if a.out:
        os.makedirs(a.out, exist_ok=True)
        with open(os.path.join(a.out, "fr_linearity.json"), "w") as f:
            json.dump(rows, f, indent=1)
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4))
        for key, r in rows.items():
            x = np.array(r["levels_dps"])
            y = np.array(r["means_dps"])
            ax.plot(x, 100 * (y - (r["scale"] * x + r["bias_dps"])) / (r["scale"] * FS_DPS),
                    "o-", ms=3, label=key + " degC")
        ax.set_xlabel("input rate [deg/s]")
        ax.set_ylabel("residual from the line [% of 300 deg/s]")
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(a.out, "fr_linearity.png"), dpi=120)
    return 0


if __name__ == "__main__":
    sys.exit(main())
