#!/usr/bin/env python3
"""Closed-loop acceptance test: run a gyro-sim scenario and check its JSON figures.

    check_scenario.py --sim PATH --scenario FILE [--set K=V ...] [--duration S]
                      [--isr-figures BENCH_JSON] [--selfcal]
                      --expect 'lock_time_s<=0.2' --expect 'q~33.33:0.02' ...

Expectations: NAME<=X, NAME>=X, NAME==X, or NAME~X:REL (within REL relative of X), or
NAME~X:+ABS (within ABS of X). X may be another figure's name (its value in the same
run), e.g. 'selfcal_q~selfcal_true_q:0.02'. A dotted NAME reaches a nested figure
(plant_warnings.pick_sense_phase.count). Prints every figure checked with its bound; exits 1 on
the first run that misses any bound, 2 on a usage error.
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile


def figure(fig, name):
    """A figure by name; a dotted name walks into nested figures (plant_warnings.LAW.count).
    None when missing, null or not a number's place."""
    node = fig
    for part in name.split("."):
        node = node.get(part) if isinstance(node, dict) else None
    return None if isinstance(node, dict) else node


def check(fig, expr):
    m = re.fullmatch(
        r"([A-Za-z0-9_.]+)\s*(<=|>=|==|~)\s*([-+0-9.eE]+|[A-Za-z_][A-Za-z0-9_.]*)"
        r"(?::(\+?)([0-9.eE+-]+))?",
        expr,
    )
    if not m:
        raise SystemExit(f"check_scenario: bad --expect '{expr}'")
    name, op, val, absflag, tol = m.groups()
    ref = re.match(r"[A-Za-z_]", val) is not None  # another figure, not a number
    for n in (name, val) if ref else (name,):
        if figure(fig, n) is None:
            return False, f"{n}: missing from the figures"
    x = float(figure(fig, name))
    v = float(figure(fig, val)) if ref else float(val)
    if ref:
        val = f"{val} = {v:.9g}"
    if op == "<=":
        ok = x <= v
    elif op == ">=":
        ok = x >= v
    elif op == "==":
        ok = x == v
    else:
        t = float(tol) if absflag else float(tol) * abs(v)
        ok = abs(x - v) <= t
        val = f"{v:g} +- {t:g}"
    return ok and math.isfinite(x), f"{name} = {x:.6g}  (expected {op} {val})"


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--sim", required=True)
    p.add_argument("--scenario", required=True)
    p.add_argument("--set", action="append", default=[])
    p.add_argument("--duration", default=None)
    p.add_argument("--isr-figures", default=None)
    p.add_argument("--selfcal", action="store_true")
    p.add_argument("--firmware-params", default=None)
    p.add_argument("--expect", action="append", default=[])
    a = p.parse_args()
    with tempfile.TemporaryDirectory() as d:
        js = os.path.join(d, "out.json")
        cmd = [a.sim, "--scenario", a.scenario, "--json", js, "--out", d]
        for s in a.set:
            cmd += ["--set", s]
        if a.duration:
            cmd += ["--duration", a.duration]
        if a.isr_figures:
            cmd += ["--isr-figures", a.isr_figures]
        if a.selfcal:
            cmd += ["--selfcal"]
        if a.firmware_params:
            cmd += ["--firmware-params", a.firmware_params]
        print(" ".join(cmd), flush=True)
        r = subprocess.run(cmd, text=True)
        if r.returncode != 0:
            print(f"gyro-sim exited {r.returncode}")
            return 1
        with open(js, encoding="utf-8") as fh:
            doc = json.load(fh)
    fig = doc["figures"]
    bad = 0
    for e in a.expect:
        ok, msg = check(fig, e)
        print(("ok   " if ok else "FAIL ") + msg)
        bad += not ok
    print(f"realtime_factor {doc.get('realtime_factor')}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
