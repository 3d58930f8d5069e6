"""tools/report and gyrotools.chapter7: the options, the conditions of every figure, the
1 s means of the compensated cool-down, the JSON's relative paths and null for NaN, and
the report's whole logic end to end (with --quick) on a stand-in simulator that answers
each scenario with canned figures and a short trace (the real campaign takes minutes).
"""
import importlib.machinery
import importlib.util
import json
import math
import os
import sys

import numpy as np
import pytest

from gyrotools import chapter7

TOOLS = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ROOT = os.path.dirname(TOOLS)

FIGURES = {
    "startup": {"lock_time_s": 0.02, "overshoot_pct": 0.06},
    "sweep": {"f0_hz": 1489.85, "q": float("nan"), "phase_at_f0_deg": -115.6},
    "square_law": {"square_law": [{"u_v": 12.75, "amp_v": 0.88}], "square_law_nonlinearity_pct": 0.013,
                   "square_law_nonlinearity_rms_pct": 0.006},
    "rate_table": {"scale_factor": 1.0002, "nonlinearity_pct": 0.0057,
                   "aout_scale_factor_v_per_dps": 0.00725, "aout_nonlinearity_pct": 0.0115},
    "brownian_only": {"arw_coeff_dph_rthz": 18.3, "brownian_floor_dph_rthz": 17.9},
    "static_allan": {"arw_deg_rth": 0.46, "adev_min_dph": 0.62, "unc_adev_min_dph": 0.6,
                     "unc_tau_at_adev_min_s": 1350},
    "drive_noise_halffreq": {"drive_amp_noise_lf_rel": 5e-6},
    "drive_noise_dcac": {"drive_amp_noise_lf_rel": 1.1e-5},
    "temp_chamber": {"residual_bias_p_dps": 0.07, "residual_bias_sensor_dps": 0.5},
    "cooldown": {"residual_bias_p_dps": 0.2, "residual_bias_sensor_dps": 5.6},
}

# A stand-in for gyro-sim: the arguments the report passes, canned figures, a trace
# whose compensated rate is +-0.1 deg/s in alternate seconds (1 s means: std 0.1, p-p
# 0.2) and whose raw rate is a ramp, and an analysis JSON with an absolute input path.
FAKE_SIM = r'''#!PYTHON
import json, os, sys
a = sys.argv[1:]
FIGURES = json.load(open(os.path.join(os.path.dirname(os.path.realpath(__file__)), "canned.json")))
def opt(k, d=None):
    return a[a.index(k) + 1] if k in a else d
scen_path = opt("--scenario")
scen = json.load(open(scen_path))
name = scen["name"]
cal = opt("--firmware-params") or (os.path.join(os.path.dirname(scen_path), scen["firmware_params"])
                                   if "firmware_params" in scen else None)
dur = float(opt("--duration", scen["duration_s"]))
os.makedirs(opt("--out"), exist_ok=True)
with open(opt("--csv"), "w") as fh:
    fh.write("t_s,rate_dps,rate_unc_dps,rate_valid\n")
    n = int(min(dur, 1000) * 10)
    for i in range(n):
        t = i / 10
        fh.write(f"{t},{0.1 if int(t) % 2 else -0.1},{t / 100},1\n")
json.dump({"input": os.path.abspath(opt("--csv"))}, open(os.path.join(opt("--out"), "tempcomp.json"), "w"))
figs = dict(FIGURES[name], args=a)
doc = {"scenario": name, "firmware_params": cal, "figures": figs,
       "params": {"seed": scen["seed"], "duration_s": dur}}
open(opt("--json"), "w").write(json.dumps(doc))
'''


def load_tool():
    loader = importlib.machinery.SourceFileLoader("report_tool", os.path.join(TOOLS, "report"))
    spec = importlib.util.spec_from_loader("report_tool", loader)
    mod = importlib.util.module_from_spec(spec)
    loader.exec_module(mod)
    return mod


@pytest.fixture
def fake_sim(tmp_path):
    p = tmp_path / "gyro-sim"
    p.write_text(FAKE_SIM.replace("PYTHON", sys.executable))
    (tmp_path / "canned.json").write_text(json.dumps(FIGURES))
    p.chmod(0o755)
    return str(p)


def strings(x):
    if isinstance(x, dict):
        for v in x.values():
            yield from strings(v)
    elif isinstance(x, list):
        for v in x:
            yield from strings(v)
    elif isinstance(x, str):
        yield x


def test_options():
    tool = load_tool()
    assert tool.parse([]).out == os.path.join(ROOT, "out", "report")
    assert tool.parse(["--publish"]).out == os.path.join(ROOT, "report")
    assert tool.parse(["--out", "x", "--quick"]).out == "x"


@pytest.mark.parametrize("args, says", [(["--publish", "--out", "x"], "--publish"),
                                        (["--bench", "/nonexistent.json"], "--bench"),
                                        (["--frobnicate"], "unrecognized")])
def test_usage_errors_are_one_line(run_script, args, says):
    code, out, err = run_script("report", args)
    assert code == 2 and says in err and err.count("\n") == 1 and err.startswith("report: error:")


def test_missing_simulator_is_one_line(run_script, tmp_path):
    code, _, err = run_script("report", ["--sim", str(tmp_path / "none"), "--out", str(tmp_path / "r")])
    assert code == 2 and "no simulator" in err and err.count("\n") == 1


def test_one_s_means():
    t = np.arange(0, 10.05, 0.05)
    y = np.where(np.floor(t).astype(int) % 2 == 1, 1.0, -1.0)
    mu = chapter7.one_s_means(t, y, 2.0)
    assert mu.size == 8 and np.allclose(mu, [-1, 1] * 4)


@pytest.mark.parametrize("part", ["default", "f1300_q200"])
def test_committed_verifications_read(part):
    with open(os.path.join(ROOT, chapter7.PARTS[part]["dir"], "report.json"), encoding="utf-8") as fh:
        v = chapter7.verification(json.load(fh))
    assert v["passed"] and len(v["plateaus_c"]) >= 3 and v["command"].startswith("tools/calibrate --sim")
    rows = chapter7.verification_rows(part, v)
    assert all(r.sample == chapter7.OUT and r.compensated == "yes" for r in rows)
    assert not any(os.path.isabs(s) for r in rows for s in r.source.split())


def test_report_end_to_end_on_a_stand_in_simulator(tmp_path, fake_sim, capsys):
    tool = load_tool()
    out = tmp_path / "rep"
    assert tool.main(["--out", str(out), "--sim", fake_sim, "--quick"]) == 0
    text = (out / "figures.json").read_text()
    doc = json.loads(text, parse_constant=lambda c: pytest.fail(f"{c} in figures.json"))
    assert not [s for s in strings(doc) if os.path.isabs(s)]
    for d, _, files in os.walk(out):
        for f in files:
            if f.endswith(".json"):
                assert '"/' not in (open(os.path.join(d, f)).read()), f
    runs = doc["runs"]

    def cal(part):
        return os.path.relpath(os.path.join(ROOT, "host_sim", "parts", part, "calibration.json"), out)
    assert runs["cooldown"]["calibration"] == cal("default")
    assert runs["brownian_only"]["calibration"] == cal("ideal")
    off = doc["figures"]["f1300_q200_startup"]["args"]
    assert "plant.f_drive_hz=1300" in off and "plant.q_drive=200" in off
    assert off[off.index("--firmware-params") + 1] == cal("f1300_q200")
    assert "--duration" in doc["figures"]["static_allan"]["args"]
    assert doc["figures"]["sweep"]["q"] is None
    comp = doc["derived"]["cooldown_comp"]
    assert comp["std_dps"] == pytest.approx(0.1) and comp["pp_dps"] == pytest.approx(0.2)
    assert doc["derived"]["cooldown_unc"]["pp_dps"] > 1.0
    table = [r for rows in doc["table"].values() for r in rows]
    assert all(r["compensated"] and r["sample"] for r in table)
    cool = [r for r in table if r["figure"].startswith("cool-down, compensated")]
    assert cool[0]["sample"] == "out of sample" and cool[0]["part"] == "default"
    assert all(r["sample"].startswith("in sample") for r in table if "fit" in r["figure"] and "residual" in r["figure"])
    md = (out / "index.md").read_text()
    assert "| part (calibration) | compensated | sample |" in md and "## Off-nominal part: f1300_q200" in md
    assert "| drive Q | n/a |" in md
    assert math.isclose(doc["verification"]["default"]["noise_ratio_1s"],
                        json.load(open(os.path.join(ROOT, "host_sim/parts/default/report.json")))
                        ["verify"]["noise"]["ratio"])


def test_a_row_must_name_the_calibration_its_run_loaded():
    rows = [chapter7.Row("f", "1", "", "default", "yes", chapter7.OUT, "cooldown")]
    runs = {"cooldown": {"calibration": "../host_sim/parts/ideal/calibration.json"}}
    with pytest.raises(ValueError, match="cooldown"):
        chapter7.check_parts(rows, runs, "..")
    runs["cooldown"]["calibration"] = "../host_sim/parts/default/calibration.json"
    chapter7.check_parts(rows, runs, "..")
