#!/usr/bin/env python3
"""Closed-loop acceptance test: run a gyro-sim scenario and check its JSON figures.

    check_scenario.py --sim PATH --scenario FILE [--set K=V ...] [--duration S]
                      [--isr-figures BENCH_JSON]
                      --expect 'lock_time_s<=0.2' --expect 'q~33.33:0.02' ...

Expectations: NAME<=X, NAME>=X, NAME==X, or NAME~X:REL (within REL relative of X), or
NAME~X:+ABS (within ABS of X). Prints every figure checked with its bound; exits 1 on
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


def check(fig, expr):
    m = re.fullmatch(r"([A-Za-z0-9_.]+)\s*(<=|>=|==|~)\s*([-+0-9.eE]+)(?::(\+?)([0-9.eE+-]+))?", expr)
    if not m:
        raise SystemExit(f"check_scenario: bad --expect '{expr}'")
    name, op, val, absflag, tol = m.groups()
    node = fig  # a dotted name walks into nested figures (plant_warnings.LAW.count)
    for part in name.split("."):
        node = node.get(part) if isinstance(node, dict) else None
    if node is None or isinstance(node, dict):
        return False, f"{name}: missing from the figures"
    x, v = float(node), float(val)
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
