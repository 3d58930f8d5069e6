#!/usr/bin/env python3
"""Warm-up of the plant's thermal network after a cold start, and the rate ramp it makes.

    thermal_warmup.py --sim GYRO_SIM [--scenario FILE] [--set KEY=V ...] [--seconds S]

The network of host_sim/plant/thermal.h, dT/dt = -L T + b Ta + h (L = diag(1/tau) +
Laplacian(g), b = 1/tau, h = rise/tau), from every node at the ambient (plant.cold_start)
at a constant ambient, in closed form: T(t) = Tss + V exp(-w t) V' (Ta - Tss) with L =
V diag(w) V' (L is symmetric). The thermal values are the default part's (`gyro-sim
--list-params`) with the scenario's "plant" settings and --set over them. Prints the
network's modes, the circuit node's warming and line fit, and what that warming makes of
the uncompensated bias (BIAS_DPS_PER_K per kelvin of the pickoff circuit, table 7-4):
its line fit and the rate ramp R that the product's Allan read-off (gyrotools.allan, as
gyro-allan) gives of it with the default part's white rate noise added. This is the
deterministic warm-up alone: the plant's circuit-phase flicker is not in it.

Exit status: 0 ok, 2 bad option or input.
"""
import argparse
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from gyrotools import allan  # noqa: E402

# Uncompensated bias per kelvin of the pickoff circuit: table 7-4, 21.21 -> 45.20 deg/s
# over 26 -> 35 degC (the default part: 2.663, test_plant test_table_7_4_slopes).
BIAS_DPS_PER_K = (45.20 - 21.21) / (35.0 - 26.0)
# White rate noise of the default part, two-sided N in deg/h/rtHz (static_allan).
WHITE_DPH_RTHZ = 27.1
FS_HZ = 10.0  # the Allan read-off's sample rate here; the long taus do not depend on it
KEYS = ("tau_struct_s", "tau_circuit_s", "tau_board_s", "couple_sc_per_s", "couple_sb_per_s",
        "couple_cb_per_s", "rise_struct_k", "rise_circuit_k", "rise_board_k", "temp_k")


def defaults(sim):
    """The default part's thermal values, as gyro-sim --list-params gives them."""
    r = subprocess.run([sim, "--list-params"], capture_output=True, text=True, check=False)
    if r.returncode != 0:
        sys.exit(f"thermal_warmup: {sim} --list-params failed ({r.returncode})")
    out = {}
    for line in r.stdout.splitlines():
        f = line.split()
        if len(f) >= 2 and f[0].startswith("plant.") and f[0][6:] in KEYS:
            out[f[0][6:]] = float(f[1])
    if set(out) != set(KEYS):
        sys.exit(f"thermal_warmup: --list-params lacks {sorted(set(KEYS) - set(out))}")
    return out


def overrides(scenario, sets):
    """The scenario's plant settings, then KEY=V settings; only the thermal ones matter."""
    out = {}
    if scenario:
        with open(scenario, encoding="utf-8") as f:
            doc = json.load(f)
        out.update({k: float(v) for k, v in doc.get("plant", {}).items() if k in KEYS})
        amb = doc.get("ambient_c")
        if amb is not None:
            if amb.get("kind") != "const":
                sys.exit("thermal_warmup: only a constant ambient_c is handled")
            out["temp_k"] = float(amb["value"]) + 273.15
    for s in sets:
        k, _, v = s.removeprefix("plant.").partition("=")
        if k not in KEYS:
            sys.exit(f"thermal_warmup: --set {s}: not a thermal value ({', '.join(KEYS)})")
        out[k] = float(v)
    return out


def network(p):
    """L, b, h of thermal.h; node order structure, circuit, board."""
    tau = np.array([p["tau_struct_s"], p["tau_circuit_s"], p["tau_board_s"]])
    sc, sb, cb = p["couple_sc_per_s"], p["couple_sb_per_s"], p["couple_cb_per_s"]
    g = np.array([[0.0, sc, sb], [sc, 0.0, cb], [sb, cb, 0.0]])
    lap = np.diag(g.sum(axis=1)) - g
    rise = np.array([p["rise_struct_k"], p["rise_circuit_k"], p["rise_board_k"]])
    return np.diag(1.0 / tau) + lap, 1.0 / tau, rise / tau


def cold_start(p, t_s):
    """Node temperatures (K) at times t_s from every node at the ambient; modes; Tss."""
    lmat, b, h = network(p)
    ta = p["temp_k"]
    tss = np.linalg.solve(lmat, b * ta + h)
    w, v = np.linalg.eigh(lmat)
    d0 = v.T @ (np.full(3, ta) - tss)
    return tss[None, :] + (np.exp(-np.outer(t_s, w)) * d0[None, :]) @ v.T, w, tss


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sim", required=True, help="gyro-sim, for the default part's values")
    ap.add_argument("--scenario", default=None, help="a scenario whose plant settings apply")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=V")
    ap.add_argument("--seconds", type=float, default=None,
                    help="run length (default: the scenario's duration_s, else 5400)")
    ap.add_argument("--seed", type=int, default=1, help="of the white noise added")
    a = ap.parse_args(argv)
    p = defaults(a.sim)
    p.update(overrides(a.scenario, a.set))
    secs = a.seconds
    if secs is None and a.scenario:
        with open(a.scenario, encoding="utf-8") as f:
            secs = float(json.load(f).get("duration_s", 5400.0))
    secs = secs or 5400.0
    t = np.arange(0.0, secs, 1.0 / FS_HZ)
    temps, w, tss = cold_start(p, t)
    ta = p["temp_k"]
    circ = temps[:, 1] - ta
    print("thermal values: " + ", ".join(f"{k} {p[k]:g}" for k in KEYS))
    print("modes (time constants): " + ", ".join(f"{1.0 / x:.0f} s" for x in w))
    print(f"steady rise above ambient: structure {tss[0] - ta:.3f}, circuit {tss[1] - ta:.3f}, "
          f"board {tss[2] - ta:.3f} K")
    for frac in (0.632, 0.9):
        k = np.argmax(circ >= frac * (tss[1] - ta)) if circ[-1] >= frac * (tss[1] - ta) else None
        when = f"{t[k]:.0f} s" if k is not None else f"not within {secs:.0f} s"
        print(f"circuit at {100 * frac:.0f} % of its rise: {when}")
    hour = min(t.size - 1, int(3600 * FS_HZ))
    print(f"circuit rise at 10 min {circ[int(600 * FS_HZ)]:.3f} K, 1 h {circ[hour]:.3f} K, "
          f"end {circ[-1]:.3f} K")
    slope_k_h = np.polyfit(t, circ, 1)[0] * 3600.0
    rng = np.random.default_rng(a.seed)
    white = rng.standard_normal(t.size) * WHITE_DPH_RTHZ * math.sqrt(FS_HZ) / 3600.0
    res = allan.analyse(BIAS_DPS_PER_K * circ + white, FS_HZ)
    r = res.rate_ramp_dph_per_s
    rr = "not resolved" if r is None else (
        f"{r * 3600:.0f} deg/h/h = {r:.3f} deg/s/h ({r / BIAS_DPS_PER_K:.3f} K/h) over "
        f"{res.ramp_tau_range_s[0]:.3g}..{res.ramp_tau_range_s[1]:.4g} s")
    print(f"uncompensated bias: Allan rate ramp {rr}")
    print(f"circuit line fit over the run: {slope_k_h:.3f} K/h, bias "
          f"{BIAS_DPS_PER_K * slope_k_h:.3f} deg/s/h at {BIAS_DPS_PER_K:.3f} deg/s/K")
    return 0


if __name__ == "__main__":
    sys.exit(main())
