#!/usr/bin/env python3
"""Parameter sets between gyro-sim and Python (docs/param-set.md).

    check_param_set.py compat   --sim PATH --scenario FILE
    check_param_set.py identity --sim PATH --scenario FILE [--duration S] [--set K=V ...]

compat: a set written by tools/gyrotools/paramset.py (every settable parameter, each float
one float32 step off its default, so no value is a default or a short decimal) is loaded
by gyro-sim (--firmware-params): the values gyro-sim runs with (its JSON "params") are the
file's bit for bit. gyro-sim writes them back (--save-params): Python reads that file, gets
the same values bit for bit, and writes the same text (params and crc32 lines).

identity: a run that saves its parameters (--save-params X, with the --set overrides)
and a run of the same scenario from that set alone (--firmware-params X) are the same
run: the CSV traces byte for byte, the JSON but for the run's speed and the set's path.
With --set, a third run without it must differ from the first (the set carried the
difference).

Exit status 0 all held, 1 one did not, 2 usage.
"""
import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from gyrotools import paramset as P  # noqa: E402

RUN_KEYS = ("realtime_factor", "realtime_factor_cpu", "firmware_params")


def sim(a, *args):
    cmd = [a.sim, "--scenario", a.scenario, "--quiet", *args]
    print(" ".join(cmd), flush=True)
    r = subprocess.run(cmd, text=True, capture_output=True, timeout=600)
    if r.returncode != 0:
        sys.stdout.write(r.stdout + r.stderr)
        raise SystemExit(f"FAIL gyro-sim exit status {r.returncode}")
    return r


def bits(d, v):
    return struct.unpack("<I", struct.pack("<f", v))[0] if d.type == "F32" else int(v)


def one_step(d):
    """The default one float32 step away from zero (toward the range), or the default."""
    if d.type != "F32" or d.default == 0.0:
        return d.default if d.type == "F32" else int(d.default)
    b = bits(d, P.f32(d.default))
    for c in (b + 1, b - 1):
        v = struct.unpack("<f", struct.pack("<I", c))[0]
        if P.f32(d.min) <= v <= P.f32(d.max):
            return v
    return d.default


def compare(table, want, got, what):
    bad = []
    for name, v in want.items():
        d = P.by_name(table)[name]
        if name not in got or bits(d, got[name]) != bits(d, v):
            bad.append(f"{what}: {name} is {got.get(name)!r}, the set says {v!r}")
    return bad


def compat(a, d):
    table = P.load_table()
    values = {p.name: one_step(p) for p in table.values() if p.settable}
    py_file, c_file, js = (os.path.join(d, n) for n in ("py.json", "c.json", "run.json"))
    P.write(py_file, P.from_values(values, meta={"made_by": "check_param_set.py"}))
    sim(a, "--duration", "0.05", "--firmware-params", py_file, "--json", js, "--save-params", c_file)
    with open(js, encoding="utf-8") as f:
        run = json.load(f)
    bad = compare(table, values, run["params"], "gyro-sim ran with")
    if run.get("firmware_params") != py_file:
        bad.append(f"JSON firmware_params is {run.get('firmware_params')!r}, not {py_file}")
    back = P.read(c_file)
    bad += compare(table, values, back.values(), "Python read gyro-sim's set")
    if [e.name for e in back.entries] != list(values):
        bad.append("gyro-sim's set does not list every settable parameter in table order")
    with open(c_file, encoding="utf-8") as f:
        c_text = f.read()
    py_text = P.dumps(P.ParamSet(back.entries))
    body = lambda t: t[t.index('  "params"'):]  # noqa: E731 - the lines after meta
    if body(py_text) != body(c_text):
        bad.append("Python writes other params/crc32 lines than gyro-sim for the same values")
    print(f"{len(values)} parameters: Python -> gyro-sim -> Python, bit for bit")
    return bad


def identity(a, d):
    sets = [x for s in a.set for x in ("--set", s)]
    common = ["--duration", str(a.duration)]
    pset = os.path.join(d, "saved.json")
    runs = {}
    for name, extra in (("saving", [*sets, "--save-params", pset]),
                        ("loading", ["--firmware-params", pset]),
                        ("plain", [])):
        if name == "plain" and not sets:
            break
        js, csv = os.path.join(d, name + ".json"), os.path.join(d, name + ".csv")
        sim(a, *common, *extra, "--json", js, "--csv", csv)
        with open(js, encoding="utf-8") as f:
            doc = json.load(f)
        with open(csv, "rb") as f:
            runs[name] = (doc, f.read())
    for doc, _ in runs.values():
        for k in RUN_KEYS:
            doc.pop(k, None)
    bad = []
    if runs["saving"][1] != runs["loading"][1]:
        bad.append("the CSV traces differ")
    if runs["saving"][0] != runs["loading"][0]:
        diff = [k for k in runs["saving"][0]["figures"]
                if runs["saving"][0]["figures"].get(k) != runs["loading"][0]["figures"].get(k)]
        bad.append(f"the JSON differs (figures {diff})")
    if "plain" in runs and runs["plain"][1] == runs["saving"][1]:
        bad.append("the --set made no difference to the run: the check cannot fail")
    print(f"runs: {', '.join(runs)}; CSV {len(runs['saving'][1])} bytes")
    return bad


def main():
    p = argparse.ArgumentParser()
    p.add_argument("mode", choices=("compat", "identity"))
    p.add_argument("--sim", required=True)
    p.add_argument("--scenario", required=True)
    p.add_argument("--duration", type=float, default=0.5)
    p.add_argument("--set", action="append", default=[], metavar="K=V")
    a = p.parse_args()
    with tempfile.TemporaryDirectory() as d:
        bad = compat(a, d) if a.mode == "compat" else identity(a, d)
    for b in bad:
        print("FAIL " + b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
