#!/usr/bin/env python3
"""Quadrature nulling held over -40..85 degC (issue 19 item 3): the default part with
nulling electrodes (20 (deg/s)/V^2, test_cl_quadnull.c's) and quad.null 1, the ambient
ramped from -40 to 85 degC at 25 K/min and held, the structure's and the circuit's
thermal time constants cut to 20 s so that the structure follows the ambient across
the whole range within the run.

    check_quadnull_temp.py GYRO_SIM [--out DIR]

Judged on the plant's truth (quad_true_dps, the quadrature the part still has): within
1 deg/s from 2 s after power-on to the end; the structure spans -39..85 degC; the nulling
voltage stays inside quad.v_max_v (10 V); never valid with the truth beyond 1 deg/s.
The fast ramp is a slew the thermometer's checks flag (THERMO_SLEW): the rate is valid
only part of the time, by design. Exit 0 pass, 1 fail, 2 run error. With --out, the
log and a plot of the residual against the structure's temperature.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
PART = os.path.join(HERE, "..", "..", "host_sim", "parts", "default", "calibration.json")
SCENARIO = {"name": "quadnull_temp", "description": "ambient -40 -> 85 degC at 25 K/min, held",
            "duration_s": 420.0, "seed": 7, "mode": "closed_loop", "csv_rate_hz": 20,
            "ambient_c": {"kind": "ramp", "value": -40, "slope_per_s": 125.0 / 300.0,
                          "t_start_s": 30, "t_end_s": 330}}
SETS = ["plant.quadnull_dps_per_v2=20", "firmware.quad.null=1",
        "firmware.cal.ref_quad_null=1",  # the calibration declared the nulling's
        "plant.tau_struct_s=20",
        "plant.tau_circuit_s=20"]
MAX_DPS = 1.0
V_MAX = 10.0


def run(sim, d):
    scen = os.path.join(d, "quadnull_temp.json")
    with open(scen, "w") as f:
        json.dump(SCENARIO, f)
    csv = os.path.join(d, "quadnull_temp.csv")
    cmd = [sim, "--scenario", scen, "--firmware-params", PART, "--quiet", "--no-analysis",
           "--csv", csv]
    for s in SETS:
        cmd += ["--set", s]
    subprocess.run(cmd, check=True)
    return np.genfromtxt(csv, delimiter=",", names=True)


def plot(t, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4))
    m = t["t_s"] > 2.0
    ax.plot(t["t_struct_c"][m], t["quad_true_dps"][m], lw=0.6)
    ax.axhline(MAX_DPS, color="k", ls="--", lw=0.8)
    ax.axhline(-MAX_DPS, color="k", ls="--", lw=0.8)
    ax.set_xlabel("structure temperature [degC]")
    ax.set_ylabel("quadrature left (plant truth) [deg/s]")
    ax.set_title("quadrature nulling, ambient -40 -> 85 degC at 25 K/min")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "quadnull_temp.png"), dpi=120)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sim")
    ap.add_argument("--out", help="folder for the log's figures and the plot")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as d:
        try:
            t = run(a.sim, d)
        except (subprocess.CalledProcessError, OSError, ValueError) as e:
            print(f"run failed: {e}")
            return 2
    m = t["t_s"] > 2.0
    q = np.abs(t["quad_true_dps"][m])
    v = np.abs(t["quadnull_v"][m])
    ts = t["t_struct_c"]
    wrong = int(np.sum((t["rate_valid"][m] != 0) & (q > MAX_DPS)))
    res = {"max_quad_left_dps": float(q.max()), "struct_c": [float(ts.min()), float(ts.max())],
           "quadnull_v": [float(v.min()), float(v.max())],
           "valid_fraction": float(np.mean(t["rate_valid"][m] != 0)), "valid_beyond": wrong,
           "sets": SETS, "scenario": SCENARIO}
    print(f"quadrature left after 2 s: max {res['max_quad_left_dps']:.3f} deg/s (limit "
          f"{MAX_DPS}); structure {ts.min():.1f} .. {ts.max():.1f} degC; nulling voltage "
          f"{v.min():.3f} .. {v.max():.3f} V; valid {100 * res['valid_fraction']:.1f} % of "
          f"the time (the ramp's slew, THERMO_SLEW), valid beyond {MAX_DPS} deg/s: {wrong}")
    if a.out:
        os.makedirs(a.out, exist_ok=True)
        with open(os.path.join(a.out, "quadnull_temp.json"), "w") as f:
            json.dump(res, f, indent=1)
        plot(t, a.out)
    ok = (q.max() <= MAX_DPS and ts.min() <= -39.0 and ts.max() >= 84.0 and v.max() < V_MAX
          and wrong == 0)
    print("pass" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
