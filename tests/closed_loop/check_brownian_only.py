#!/usr/bin/env python3
"""The brownian_only scenario keeps every source but the Brownian force off.

    check_brownian_only.py --sim GYRO_SIM --scenario BROWNIAN_ONLY_JSON

Its figure compares the rate noise with the thermomechanical floor (4-24), so any other
source left on (an electronic noise, a flicker, a drift, a jitter, a converter's INL, a
nonlinearity) would make it a comparison with something else. The plant parameters of a
short run (the JSON's "params", after the scenario's preset and settings) are checked by
name: every parameter whose name says it is a noise, flicker, jitter, drift, INL,
nonlinearity or a Q law must be 0, and "brownian" must be 1. The name patterns cover the
sources added later too, as long as they are named like the ones here; a parameter that
matches a pattern but is only a shape (a corner frequency, a correlation time, a pair
imbalance) is listed in SHAPES. Exit 0: all off; 1: one is on (named); 2: usage or run
error.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

# a source of something other than Brownian noise, by its parameter's name
SOURCE = re.compile(r"noise|flicker|jitter|drift|inl_|_gap_m$|^fb_gap_m$|^k3_|q_temp_law|nl_")
# shapes of a source, not a source: 1/f corners, correlation times, pickoff pair imbalance
SHAPES = re.compile(r"_fmin_hz$|_tau_s$|_gap_asym$")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sim", required=True)
    ap.add_argument("--scenario", required=True)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "b.json")
        run = subprocess.run([args.sim, "--scenario", args.scenario, "--duration", "0.01",
                              "--no-analysis", "--json", out],
                             capture_output=True, text=True, timeout=120)
        if run.returncode != 0:
            print(f"gyro-sim failed ({run.returncode}): {run.stderr.strip()}")
            return 2
        with open(out, encoding="utf-8") as f:
            params = json.load(f)["params"]
    on = [k for k, v in params.items()
          if SOURCE.search(k) and not SHAPES.search(k) and isinstance(v, (int, float)) and v != 0]
    checked = [k for k in params if SOURCE.search(k) and not SHAPES.search(k)]
    print(f"plant_preset = {params.get('plant_preset')}; {len(checked)} source parameters "
          f"checked: {', '.join(checked)}")
    if params.get("brownian") != 1:
        print(f"brownian = {params.get('brownian')} (expected 1)")
        return 1
    if on:
        print("on besides the Brownian force: " + ", ".join(f"{k} = {params[k]:g}" for k in on))
        return 1
    print("only the Brownian force is on")
    return 0


if __name__ == "__main__":
    sys.exit(main())
