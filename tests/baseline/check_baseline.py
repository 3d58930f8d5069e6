#!/usr/bin/env python3
"""Behaviour baseline: the start-up scenario's CSV and the host twin's rate trace, byte for
byte, against the digests in baseline.sha256.

A change that is meant to leave the drive and rate behaviour alone (a refactor, a new
command, a new status line) must leave both digests as they are. A change that is meant
to alter behaviour updates baseline.sha256 in its own commit, saying why; the files to
compare against are regenerated from the commit named there:

    git worktree add /tmp/base COMMIT && (cd /tmp/base && cmake --preset host && \
      cmake --build --preset host --target gyro-sim fw_qemu_twin)

    check_baseline.py --sim GYRO_SIM --twin FW_QEMU_TWIN --scenario STARTUP_JSON [--update]

Exit codes: 0 identical, 1 different, 2 usage or a program failed.
"""
import argparse
import hashlib
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
DIGESTS = os.path.join(HERE, "baseline.sha256")


def read_digests():
    out = {}
    with open(DIGESTS, encoding="ascii") as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            digest, name = line.split()
            out[name] = digest
    return out


def produce(args, tmp):
    csv = os.path.join(tmp, "startup.csv")
    sim = subprocess.run([args.sim, "--scenario", args.scenario, "--csv", csv,
                          "--json", os.path.join(tmp, "startup.json")],
                         capture_output=True, text=True, timeout=300)
    if sim.returncode != 0:
        sys.exit(f"gyro-sim failed ({sim.returncode}): {sim.stderr.strip()}")
    twin = subprocess.run([args.twin], capture_output=True, timeout=300)
    if twin.returncode != 0:
        sys.exit(f"fw_qemu_twin failed ({twin.returncode})")
    with open(csv, "rb") as f:
        csv_bytes = f.read()
    return {"startup.csv": csv_bytes, "twin.txt": twin.stdout}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sim", required=True)
    ap.add_argument("--twin", required=True)
    ap.add_argument("--scenario", required=True)
    ap.add_argument("--update", action="store_true",
                    help="rewrite baseline.sha256 from this build (a deliberate change)")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        got = {k: hashlib.sha256(v).hexdigest() for k, v in produce(args, tmp).items()}
    if args.update:
        with open(DIGESTS, "w", encoding="ascii") as f:
            f.write("# sha256 of the start-up scenario's CSV and the host twin's trace\n")
            for k in sorted(got):
                f.write(f"{got[k]}  {k}\n")
        print("baseline.sha256 rewritten")
        return 0
    want = read_digests()
    bad = [k for k in sorted(want) if got.get(k) != want[k]]
    for k in sorted(want):
        print(f"{k}: {'identical' if k not in bad else 'DIFFERENT ' + got.get(k, '-')}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
