#!/usr/bin/env python3
"""tools/calibrate against gyro-sim.

  check_calibration.py regen GYRO_SIM   the default part's flow run again reproduces the
                                        committed host_sim/parts/default/calibration.json
                                        (every value but cal.date, to 1e-6 relative) and
                                        its verification passes (exit 0)
  check_calibration.py usage GYRO_SIM   bad input is refused with exit 2 and a message,
                                        nothing written
  check_calibration.py defaults GYRO_SIM  gyro-scalefactor and gyro-demodcal, run with
                                        their defaults on the shipped rate table's log,
                                        give the default part's calibrated values back
  check_calibration.py tempcomp GYRO_SIM  the default part's committed compensation out
                                        of sample: at ambients the thermal calibration
                                        never used (-25 and 50 degC, the part starting
                                        there), the rate valid, at rest within 0.2 deg/s,
                                        and the scale factor (+-100 deg/s) within 500 ppm
  check_calibration.py quick GYRO_SIM   an off-nominal part (1300 Hz, Q 200) through
                                        tools/calibrate --quick: verified, right at
                                        25 degC, never a valid rate at 60 degC (outside
                                        the quick protocol's 15..35 degC)
  check_calibration.py quick_vacuum GYRO_SIM   the same for a vacuum part (Q 2e4: the
                                        tracking drive and its frequency thermometer)
  check_calibration.py quick_fr GYRO_SIM   a part for closed-loop sense through
                                        tools/calibrate --quick --sense fr --quad-null:
                                        the same, its configuration recorded
  check_calibration.py brownian_highq GYRO_SIM   issue 16's floor at high Q: the ideal
                                        part at drive Q 1e4 calibrated by tools/calibrate
                                        --quick, then brownian_only with that calibration:
                                        the valid output's noise within 10 % of (4-24)
  check_calibration.py noise GYRO_SIM  the compensation's cost in noise with the default
                                        part's committed calibration: static_allan (seed 4,
                                        noise the flow's verification never saw) for 640 s,
                                        the Allan deviation of rate_dps within 1.1x that of
                                        rate_unc_dps at 1 s and at 10 s (thermcal.verify_noise)
  check_calibration.py port_quick GYRO_SIM   the flow over a UART: the default part
                                        behind gyro-sim --uart-pty --pace 0, calibrated by
                                        tools/calibrate --port --bench emu --quick (the
                                        simulated bench moving its table and chamber):
                                        verified, its part id recorded, and the
                                        calibration right at 25 degC on a gyro-sim run of
                                        its own (a profile and noise it never saw)
  check_calibration.py commands GYRO_SIM  a scenario's "commands" (what the flow's
                                        self-test stage uses) reach the command line at
                                        their times; one due after the run has no reply
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from gyrotools import paramset  # noqa: E402

CAL = os.path.join(ROOT, "host_sim", "parts", "default", "calibration.json")
TOOL = os.path.join(ROOT, "tools", "calibrate")


def run(args):
    return subprocess.run([sys.executable, TOOL] + args, capture_output=True, text=True)


def regen(sim):
    committed = paramset.read(CAL)
    with tempfile.TemporaryDirectory() as d:
        # The committed file's own command, with this build's simulator.
        cmd = committed.meta["command"].split()[1:]
        out = cmd.index("--out")
        cmd[out + 1] = d
        r = run(cmd + ["--gyro-sim", sim])
        print(r.stdout + r.stderr)
        if r.returncode != 0:
            print(f"FAIL: exit {r.returncode}")
            return 1
        new = paramset.read(os.path.join(d, "calibration.json")).values()
    bad = 0
    for name, want in committed.values().items():
        if name == "cal.date":
            continue
        got = new[name]
        if abs(got - want) > 1e-6 * max(abs(want), 1e-30):
            print(f"FAIL: {name} {got!r}, committed {want!r}")
            bad += 1
    print("ok: the flow reproduces the committed calibration" if bad == 0 else "")
    return 1 if bad else 0


def usage(sim):
    cases = [
        (["--sim", "--set", "firmware.rate.scale_dps=1", "--out", "X"], "only plant.KEY=V"),
        (["--sim", "--set", "plant.q_drive", "--out", "X"], "only plant.KEY=V"),
        (["--sim", "--out", "X", "--gyro-sim", "/nonexistent/gyro-sim"], "no simulator"),
        (["--sim", "--seed", "-1", "--out", "X"], "--seed"),
        (["--out", "X"], "--sim"),
        (["--sim", "--fb-scheme", "dcac", "--out", "X"], "needs --sense fr"),
        (["--sim", "--tune", "matched", "--out", "X"], "needs --sense fr"),
        (["--sim", "--sense", "closed", "--out", "X"], "invalid choice"),
        (["--sim", "--sense", "fr", "--verify-only", CAL, "--out", "X"], "its own configuration"),
        (["--sim", "--board-temp", "--verify-only", CAL, "--out", "X"], "no --board-temp"),
        (["--port", "/dev/null", "--part-id", "1", "--board-temp", "--out", "X"], "--sim only"),
    ]
    bad = 0
    with tempfile.TemporaryDirectory() as d:
        for args, want in cases:
            args = [a if a != "X" else os.path.join(d, "out") for a in args]
            if "--gyro-sim" not in args:
                args += ["--gyro-sim", sim]
            r = run(args)
            ok = r.returncode == 2 and want in r.stderr and "Traceback" not in r.stderr \
                and not os.path.exists(os.path.join(d, "out", "calibration.json"))
            print(f"{'ok  ' if ok else 'FAIL'} {' '.join(args)} -> {r.returncode}: "
                  f"{r.stderr.strip()[:120]}")
            bad += not ok
    return 1 if bad else 0


def run_sim(sim, scen, extra):
    """gyro-sim on a scenario, quietly; False (and why, printed) if it failed."""
    r = subprocess.run([sim, "--scenario", scen, "--quiet", "--no-analysis"] + extra,
                       capture_output=True, text=True)
    if r.returncode != 0:
        print(f"FAIL: gyro-sim exit {r.returncode}: {r.stderr}")
    return r.returncode == 0


def tool_defaults(sim):
    scen = os.path.join(ROOT, "host_sim", "scenarios", "rate_table.json")
    cal = paramset.read(CAL).values()
    bad = 0
    with tempfile.TemporaryDirectory() as d:
        csv = os.path.join(d, "rt.csv")
        if not run_sim(sim, scen, ["--csv", csv]):
            return 1
        runs = [("gyro-scalefactor", [csv]),
                ("gyro-demodcal", [csv, "--phase-deg", repr(cal["rate.demod_phase_deg"]),
                                   "--scale", repr(cal["rate.scale_dps"])])]
        for tool, args in runs:
            out = os.path.join(d, tool)
            r = subprocess.run([sys.executable, os.path.join(ROOT, "tools", tool)] + args
                               + ["--out", out], capture_output=True, text=True)
            print(f"{tool} (defaults): exit {r.returncode}: "
                  f"{(r.stdout + r.stderr).strip().splitlines()[-2:]}")
            if r.returncode != 0:
                bad += 1
                continue
            js = os.path.join(out, tool.replace("gyro-", "") + ".json")
            with open(js, encoding="utf-8") as fh:
                j = json.load(fh)
            gain = j["scale_factor_out_per_dps"] if tool == "gyro-scalefactor" else j["gain"]
            if abs(gain - 1.0) > 500e-6:
                print(f"FAIL: {tool}: gain {gain}, not within 500 ppm of the calibration's")
                bad += 1
    print("ok" if bad == 0 else "FAIL")
    return 1 if bad else 0


# tempcomp: the part starts at the ambient (the plant's thermal nodes at rest there); the
# table rests, turns at +R, -R, +R (as the flow's plateaus). Judged windows (s): rest,
# +R, -R, +R.
TC_AMBIENTS_C = (-25.0, 50.0)
TC_RATE_DPS = 100.0
TC_STEPS = [[3.0, 0.0], [3.0, TC_RATE_DPS], [3.0, -TC_RATE_DPS], [3.0, TC_RATE_DPS], [0.5, 0.0]]
TC_WINDOWS = ((1.0, 3.0), (4.0, 6.0), (7.0, 9.0), (10.0, 12.0))
TC_BIAS_DPS, TC_SF_PPM = 0.2, 500.0


def plateau(sim, cal, amb, d, sets=(), lead_s=0.0):
    """The part (plant sets) with calibration cal started at ambient amb, after lead_s at
    rest the table's rest, +R, -R, +R: (valid fraction per window, bias, scale-factor
    error in ppm, the structure's temperature), or None if gyro-sim failed."""
    steps = ([[lead_s, 0.0]] if lead_s > 0.0 else []) + TC_STEPS
    scen = os.path.join(d, "tc.json")
    with open(scen, "w", encoding="utf-8") as fh:
        json.dump({"name": "tempcomp_oos", "description": "out-of-sample plateau",
                   "mode": "closed_loop", "seed": 4242, "analyses": [],
                   "duration_s": sum(s[0] for s in steps), "csv_rate_hz": 200,
                   "firmware_params": cal, "ambient_c": {"kind": "const", "value": amb},
                   "rate_dps": {"kind": "steps", "edge_s": 0.2, "steps": steps}}, fh)
    csv = os.path.join(d, "tc.csv")
    extra = ["--csv", csv] + [a for s in sets for a in ("--set", s)]
    if not run_sim(sim, scen, extra):
        return None
    x = np.genfromtxt(csv, delimiter=",", names=True)
    w = [(x["t_s"] >= a + lead_s) & (x["t_s"] < b + lead_s) for a, b in TC_WINDOWS]
    valid = [float(np.mean(x["rate_valid"][m])) for m in w]
    bias = float(np.mean(x["rate_dps"][w[0]]))
    pos = 0.5 * (np.mean(x["rate_dps"][w[1]]) + np.mean(x["rate_dps"][w[3]]))
    sf_ppm = ((pos - np.mean(x["rate_dps"][w[2]])) / (2 * TC_RATE_DPS) - 1.0) * 1e6
    return valid, bias, sf_ppm, float(np.mean(x["t_struct_c"][w[0]]))


def plateau_ok(res, amb):
    valid, bias, sf_ppm, t_struct = res
    ok = min(valid) == 1.0 and abs(bias) <= TC_BIAS_DPS and abs(sf_ppm) <= TC_SF_PPM
    print(f"{'ok  ' if ok else 'FAIL'} {amb:g} degC (structure {t_struct:.2f} degC): bias "
          f"{bias:+.4f} deg/s, scale factor {sf_ppm:+.1f} ppm, valid in the windows (%): "
          + " ".join(f"{100 * v:.0f}" for v in valid))
    return ok


def tempcomp_out_of_sample(sim):
    bad = 0
    with tempfile.TemporaryDirectory() as d:
        for amb in TC_AMBIENTS_C:
            res = plateau(sim, CAL, amb, d)
            if res is None:
                return 1
            bad += not plateau_ok(res, amb)
    return 1 if bad else 0


# quick: an off-nominal part through tools/calibrate --quick (15..35 degC): verified (exit
# 0), right at 25 degC, and at 60 degC, outside its span, never a valid rate.
QUICK_PART = ("plant.f_drive_hz=1300", "plant.q_drive=200")
# quick_vacuum: the same for a vacuum part (drive Q 2e4, thermoelastic Q law; a quarter
# less sense gain, as the vacuum family's, for the undamped sense response's headroom):
# its sweep commits the tracking drive, so the flow calibrates the tracking drive, with
# the tracked frequency as thermometer, and records it (cal.ref_track 1). Judged after 20 s
# at rest: the rate reference's wide start lasts 4 drive time constants (2Q/wn = 4.3 s).
VACUUM_PART = ("plant.q_drive=20000", "plant.q_sense=2000", "plant.q_temp_law=2",
               "plant.pick_sense_gain_v_per_m=46350000")


def calibration_of(r, out):
    """The calibration tools/calibrate wrote into out, its output printed; None (and why)
    when it did not exit 0."""
    print(r.stdout + r.stderr)
    if r.returncode != 0:
        print(f"FAIL: exit {r.returncode}")
        return None
    return os.path.join(out, "calibration.json")


def quick_part(sim, part, track, lead_s, config=(), want=None):
    """part through tools/calibrate --quick in the sense configuration config (its
    options): verified, right at 25 degC, never valid at 60 degC, the drive mode track and
    the calibration's values want (name -> value) recorded."""
    with tempfile.TemporaryDirectory() as d:
        sets = [a for s in part for a in ("--set", s)]
        cal = calibration_of(run(["--sim", "--quick", "--seed", "7", "--out", d, "--gyro-sim",
                                  sim] + sets + list(config)), d)
        if cal is None:
            return 1
        values = paramset.read(cal).values()
        mode = values["cal.ref_track"]
        recorded = all(values[k] == v for k, v in (want or {}).items())
        print(f"{'ok  ' if recorded else 'FAIL'} recorded: "
              + ", ".join(f"{k} {values[k]:g} (expected {v:g})" for k, v in (want or {}).items()))
        inside = plateau(sim, cal, 25.0, d, part, lead_s)
        outside = plateau(sim, cal, 60.0, d, part, lead_s)
    if inside is None or outside is None:
        return 1
    ok = plateau_ok(inside, 25.0)
    never = max(outside[0]) == 0.0
    print(f"{'ok  ' if never else 'FAIL'} 60 degC, outside the quick calibration's span: valid "
          "in the windows (%): " + " ".join(f"{100 * v:.0f}" for v in outside[0]))
    print(f"{'ok  ' if mode == track else 'FAIL'} cal.ref_track {mode} (expected {track})")
    return 0 if ok and never and mode == track and recorded else 1


def quick(sim):
    return quick_part(sim, QUICK_PART, 0, 0.0)


def port_quick(sim):
    with tempfile.TemporaryDirectory() as d:
        pty = os.path.join(d, "gyro.pty")
        proc = subprocess.Popen([sim, "--scenario", os.path.join(ROOT, "host_sim", "scenarios",
                                                                 "startup.json"),
                                 "--duration", "1000000", "--quiet", "--pace", "0",
                                 f"--uart-pty={pty}"], stdout=subprocess.PIPE, text=True)
        try:
            proc.stdout.readline()
            out = os.path.join(d, "cal")
            r = run(["--port", pty, "--bench", "emu", "--part-id", "7", "--quick",
                     "--out", out])
        finally:
            proc.terminate()
            proc.wait(timeout=30)
        cal = calibration_of(r, out)
        if cal is None:
            return 1
        pid = paramset.read(cal).values()["cal.part_id"]
        inside = plateau(sim, cal, 25.0, d)
    if inside is None:
        return 1
    ok = plateau_ok(inside, 25.0)
    print(f"{'ok  ' if pid == 7 else 'FAIL'} cal.part_id {pid} (expected 7)")
    return 0 if ok and pid == 7 else 1


def quick_vacuum(sim):
    return quick_part(sim, VACUUM_PART, 1, 20.0)


# quick_fr: a part for closed-loop sense through the flow in force rebalance with
# quadrature nulling (tools/calibrate --sense fr --quad-null): its sense mode at 1600 Hz
# of Q 1e4 (a 110 Hz split; open loop its quadrature would clip the ADC), the
# half-frequency feedback pair and nulling electrodes of tools/gyrotools/frpart.py and
# frnoise.py. Its converters are linear (no per-code INL): force rebalance reads the
# rate from the force the feedback converter makes, so that converter's INL is the
# scale's nonlinearity. On the default board's (plant.dac_inl_code_lsb 1.75) the same
# flow measured sub-range slopes of -763 ppm (110..230 deg/s; the limit 500) and failed
# its verification, exit 3: README, "Calibrating closed-loop sense".
FR_PART = ("plant.f_sense_hz=1600", "plant.q_sense=1e4", "plant.fb_mode=3",
           "plant.ks_fb_mps2_per_v2=0.1", "plant.quadnull_dps_per_v2=20",
           "plant.dac_inl_code_lsb=0")


def quick_fr(sim):
    return quick_part(sim, FR_PART, 0, 0.0, ["--sense", "fr", "--quad-null"],
                      {"cal.ref_sense_mode": 1, "cal.ref_quad_null": 1, "sense.mode": 1})


# brownian_highq: the Brownian floor (4-24) at drive Q 1e4 through a calibration of that
# part. The floor is the sense mode's force noise, the same whatever the drive's Q; what a
# high drive Q adds is the quadrature turned by the drive's Brownian phase noise. Judged
# on a calibration of this part: with another part's (the default calibration after a
# --selfcal sweep) the rate is never valid and its scale factor is 0.79 (the compensation
# reads the rate's turn of P, Q times larger at Q 1e4, as temperature), so the
# input-referred noise read 1.24x the floor while the output's own noise sat on it.
BROWNIAN_PART = ("plant.preset=ideal", "plant.q_drive=10000")


def brownian_highq(sim):
    with tempfile.TemporaryDirectory() as d:
        sets = [a for s in BROWNIAN_PART for a in ("--set", s)]
        r = run(["--sim", "--quick", "--out", d, "--gyro-sim", sim] + sets)
        print(r.stdout[-2000:] + r.stderr)
        if r.returncode != 0:
            print(f"FAIL: calibration exit {r.returncode}")
            return 1
        js = os.path.join(d, "bo.json")
        scen = os.path.join(ROOT, "host_sim", "scenarios", "brownian_only.json")
        r = subprocess.run([sim, "--scenario", scen, "--quiet", "--firmware-params",
                            os.path.join(d, "calibration.json"), "--set", "plant.q_drive=10000",
                            "--json", js, "--out", os.path.join(d, "bo")],
                           capture_output=True, text=True)
        if r.returncode != 0:
            print(f"FAIL: gyro-sim exit {r.returncode}: {r.stderr}")
            return 1
        with open(js, encoding="utf-8") as fh:
            f = json.load(fh)["figures"]
    # 1200 s of white noise: the Allan fit's own scatter is about 3 % (the scenario's
    # note), so 10 % is the goal with room for it; valid once the start-up
    # (4 drive time constants, 8.6 s) is over; the scale factor is its calibration's.
    checks = [("arw_over_floor", abs(f["arw_over_floor"] - 1.0) <= 0.10),
              ("rate_valid_fraction", f["rate_valid_fraction"] >= 0.95),
              ("scale_factor", abs(f["scale_factor"] - 1.0) <= 0.01)]
    for name, ok in checks:
        print(f"{'ok  ' if ok else 'FAIL'} {name} {f[name]:.4f}")
    return 0 if all(ok for _, ok in checks) else 1


def commands(sim):
    scen = os.path.join(ROOT, "tests", "vectors", "scenario_commands.json")
    freq = paramset.read(CAL).values()["drive.freq_hz"]
    with tempfile.TemporaryDirectory() as d:
        js = os.path.join(d, "r.json")
        if not run_sim(sim, scen, ["--json", js]):
            return 1
        with open(js, encoding="utf-8") as fh:
            got = json.load(fh)["commands"]
    for c in got:
        print(f"{c['t_s']:g} {c['line']!r} -> {c['reply']!r}")
    ok = (len(got) == 3 and "- calibrated yes\r\n" in got[0]["reply"]
          and got[1]["reply"].startswith(f"ok drive.freq_hz {paramset.format_f32(freq)} Hz")
          and got[2]["reply"] is None)
    print("ok" if ok else "FAIL")
    return 0 if ok else 1


NOISE_RUN_S = 640.0  # NOISE_10S_MIN_WINDOWS windows of 10 s after the start-up left out


def noise(sim):
    from gyrotools import csvlog, thermcal
    scen = os.path.join(ROOT, "host_sim", "scenarios", "static_allan.json")
    with tempfile.TemporaryDirectory() as d:
        csv = os.path.join(d, "noise.csv")
        if not run_sim(sim, scen, ["--duration", f"{NOISE_RUN_S:g}", "--csv", csv,
                                   "--csv-rate", "100", "--firmware-params", CAL]):
            return 1
        log = csvlog.read_log(csv, need=["rate_dps", "rate_unc_dps"])
        r = thermcal.verify_noise(log, thermcal.FULL)
    print(f"noise: Allan deviation ratio compensated / uncompensated {r['ratio']:.3f} at 1 s, "
          f"{r['ratio_10s']:.3f} at 10 s ({r['adev_10s_compensated_dph']:.1f} / "
          f"{r['adev_10s_uncompensated_dph']:.1f} deg/h), 10 s judged: {r['ratio_10s_judged']}")
    ok = r["ok"] and r["ratio_10s_judged"]
    print("ok" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    modes = {"regen": regen, "usage": usage, "commands": commands, "defaults": tool_defaults,
             "tempcomp": tempcomp_out_of_sample, "quick": quick, "quick_vacuum": quick_vacuum,
             "quick_fr": quick_fr,
             "brownian_highq": brownian_highq, "noise": noise, "port_quick": port_quick}
    if len(sys.argv) != 3 or sys.argv[1] not in modes:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(modes[sys.argv[1]](sys.argv[2]))
