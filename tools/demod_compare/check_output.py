#!/usr/bin/env python3
"""ctest smoke test of demod-compare: run it with a few realisations and check that the
JSON has exactly the documented shape, the CSV matches it, the PNG is written, and the
figures are physically sane.

usage: check_output.py DEMOD_COMPARE_EXE WORK_DIR
"""
import csv
import json
import math
import os
import subprocess
import sys

DEMODS = {"lmsd", "rlsd", "kfd", "mult"}
SETS = {"thesis", "equal_bandwidth"}
KEYS = {"demodulator", "set", "param", "mse_db", "settle_s", "gain_100hz",
        "phase_100hz_deg", "bw_3db_hz"}
RUNS = 12


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def check(cond, msg):
    if not cond:
        fail(msg)


def main(argv):
    exe, work = argv[1], argv[2]
    os.makedirs(work, exist_ok=True)
    jpath, cpath, ppath = (os.path.join(work, n) for n in ("r.json", "r.csv", "r.png"))
    for p in (jpath, cpath, ppath):
        if os.path.exists(p):
            os.remove(p)
    out = subprocess.run([exe, "--runs", str(RUNS), "--seed", "7", "--json", jpath, "--csv",
                          cpath, "--png", ppath], capture_output=True, text=True)
    print(out.stdout)
    check(out.returncode == 0, "exit code %d: %s" % (out.returncode, out.stderr))
    bad = subprocess.run([exe, "--runs", "0"], capture_output=True, text=True)
    check(bad.returncode != 0, "--runs 0 accepted")

    with open(jpath) as f:
        res = json.load(f)
    check(set(res.keys()) == {"protocol", "results"}, "top-level keys %s" % list(res))
    p = res["protocol"]
    check(p["runs"] == RUNS and p["fs_hz"] == 50000 and p["carrier_hz"] == 1750,
          "protocol %s" % p)
    check(p["amplitude"] == 0.01 and p["noise_sigma"] == 0.002, "signal levels")
    r = res["results"]
    check(len(r) == 8, "%d results" % len(r))
    check({(x["demodulator"], x["set"]) for x in r} ==
          {(d, s) for d in DEMODS for s in SETS}, "every demodulator in every set")
    by = {}
    for x in r:
        check(set(x.keys()) == KEYS, "keys %s" % sorted(x))
        by[(x["demodulator"], x["set"])] = x
        for k in KEYS - {"demodulator", "set", "bw_3db_hz"}:
            check(isinstance(x[k], (int, float)) and math.isfinite(x[k]), "%s %s" % (k, x))
        check(-90 < x["mse_db"] < -60, "MSE %s" % x)
        check(0 < x["settle_s"] < 0.05, "settling %s" % x)
        check(0.3 < x["gain_100hz"] < 0.9, "gain at 100 Hz %s" % x)
        check(-300 < x["phase_100hz_deg"] < -150, "phase at 100 Hz %s" % x)

    # thesis parameters
    check(by[("lmsd", "thesis")]["param"] == 0.034, "thesis mu")
    check(by[("rlsd", "thesis")]["param"] == 0.982, "thesis lambda")
    check(by[("kfd", "thesis")]["param"] == 0.3, "thesis R")
    check(by[("mult", "thesis")]["bw_3db_hz"] is None, "bare multiplier has no band limit")
    # LMSD's measured bandwidth agrees with lmsd_bandwidth_hz() (lmsd.h): 280 Hz at 0.034
    bw_l = by[("lmsd", "thesis")]["bw_3db_hz"]
    check(abs(bw_l / 280.2 - 1) < 0.02, "LMSD bandwidth %s vs 280 Hz" % bw_l)
    # RLSD and KFD at the thesis parameters: pole 0.982, about 145 Hz (rlsd.h, kfd.h)
    for d in ("rlsd", "kfd"):
        bw = by[(d, "thesis")]["bw_3db_hz"]
        check(120 < bw < 170, "%s thesis bandwidth %s" % (d, bw))

    # equal-bandwidth set: measured bandwidths within 5 % of each other and of the target
    bws = [by[(d, "equal_bandwidth")]["bw_3db_hz"] for d in DEMODS]
    check(all(b is not None for b in bws), "equal-bandwidth set has bandwidths")
    check(max(bws) / min(bws) < 1.05, "equal bandwidths %s" % bws)
    check(abs(bws[0] / p["bw_target_hz"] - 1) < 0.05, "target %s" % p["bw_target_hz"])
    # ... and then (white noise, same bandwidth) MSEs within 1 dB of each other
    mses = [by[(d, "equal_bandwidth")]["mse_db"] for d in DEMODS]
    check(max(mses) - min(mses) < 1.0, "equal-bandwidth MSEs %s" % mses)

    with open(cpath, newline="") as f:
        rows = list(csv.reader(f))
    head = rows[0]
    check(head[0] == "t_s" and len(head) == 25, "CSV header %s" % head)
    n = round((p["mse_window_end_s"]) * p["fs_hz"])
    check(len(rows) - 1 == n, "CSV rows %d, expected %d" % (len(rows) - 1, n))
    check(all(len(row) == 25 for row in rows), "ragged CSV")
    last = [float(v) for v in rows[-1][1:9]]
    check(all(abs(v / 0.01 - 1) < 0.05 for v in last), "mean step responses end at A: %s" % last)
    check(os.path.getsize(ppath) > 10000, "PNG missing or empty")
    with open(ppath, "rb") as f:
        check(f.read(8) == b"\x89PNG\r\n\x1a\n", "PNG signature")
    print("demod-compare output OK")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
