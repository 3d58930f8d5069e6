#!/usr/bin/env python3
"""gyro-sim refusing or failing as documented: its exit status, its message, and whether
the JSON was written.

    check_sim_exit.py --sim PATH --exit N --stderr REGEX [--json-key KEY ...]
                      [--no-json] -- GYRO_SIM_ARGS...

Runs gyro-sim with GYRO_SIM_ARGS plus --json into a temporary folder. Checks the exit
status is N and stderr matches REGEX; --no-json: no JSON was written (nothing ran);
--json-key: the JSON was written and has KEY at its top level or in its figures.
Exit status 0 all held, 1 one did not, 2 usage.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--sim", required=True)
    p.add_argument("--exit", type=int, required=True)
    p.add_argument("--stderr", required=True)
    p.add_argument("--json-key", action="append", default=[])
    p.add_argument("--no-json", action="store_true")
    p.add_argument("args", nargs=argparse.REMAINDER)
    a = p.parse_args()
    args = a.args[1:] if a.args[:1] == ["--"] else a.args
    with tempfile.TemporaryDirectory() as d:
        js = os.path.join(d, "out.json")
        cmd = [a.sim, *args, "--json", js]
        print(" ".join(cmd), flush=True)
        r = subprocess.run(cmd, text=True, capture_output=True, timeout=600)
        sys.stdout.write(r.stdout)
        sys.stdout.write(r.stderr)
        bad = []
        if r.returncode != a.exit:
            bad.append(f"exit status {r.returncode}, expected {a.exit}")
        if not re.search(a.stderr, r.stderr):
            bad.append(f"stderr does not match '{a.stderr}'")
        if a.no_json and os.path.exists(js):
            bad.append("a JSON was written: something ran")
        if a.json_key:
            if not os.path.exists(js):
                bad.append("no JSON written")
            else:
                with open(js, encoding="utf-8") as fh:
                    doc = json.load(fh)
                for k in a.json_key:
                    if k not in doc and k not in doc.get("figures", {}):
                        bad.append(f"{k}: not in the JSON")
    for b in bad:
        print("FAIL " + b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
