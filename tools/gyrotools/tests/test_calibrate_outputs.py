"""tools/calibrate's outputs by verdict: a verified calibration is DIR/calibration.json; one
whose verification failed is left as DIR/calibration_unverified.json only (the 1300 Hz,
Q 200 part's gave valid rates 1.27 deg/s wrong in its ramp: it must not be loaded by
mistake), and an earlier run's calibration.json in the same folder does not survive it.
The flow's stages are replaced by doubles (the real ones take minutes of simulation)."""

import importlib.machinery
import importlib.util
import json
import os

import numpy as np
import pytest

from gyrotools import calflow, csvlog, paramset

TOOL = os.path.join(os.path.dirname(__file__), "..", "..", "calibrate")


def load_tool():
    loader = importlib.machinery.SourceFileLoader("calibrate_tool", TOOL)
    spec = importlib.util.spec_from_loader("calibrate_tool", loader)
    mod = importlib.util.module_from_spec(spec)
    loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("passed", [True, False])
def test_only_a_verified_calibration_is_calibration_json(tmp_path, monkeypatch, passed):
    tool = load_tool()
    values = {d.name: d.default for d in paramset.load_table().values()
              if "persist" in d.flags and "read-only" not in d.flags}
    values["drive.freq_hz"] = 1489.9
    monkeypatch.setattr(calflow, "selfcal", lambda part: ("x", {"f0_hz": 1489.9, "q": 33.0}))
    monkeypatch.setattr(calflow, "rate_table", lambda part, path: (dict(values), [
        {"alpha_deg": 0.0, "gain": 1.0}]))
    monkeypatch.setattr(calflow, "linearity", lambda part, v: (v, {
        "rates_dps": [280], "slope": 1.0, "correction_at_fs": [0.0, 0.0],
        "residual_rms_dps_linear": 0.01, "residual_rms_dps_linearised": 0.01}))
    monkeypatch.setattr(calflow, "thermal", lambda part, v: (v, {
        "plateaus_c": [-40.0, 85.0], "p_span_deg": 1.0, "fit_rms_1s_dps": 0.1}))
    monkeypatch.setattr(calflow, "selftest", lambda part, v, *lock: (v, {
        "expect_dps": 5.5, "cont_expect_dps": 4.2}))
    monkeypatch.setattr(calflow, "verify_all", lambda part, cal: {"stub": {"ok": passed}})
    monkeypatch.setattr(tool, "summarise", lambda res: None)
    sim = tmp_path / "gyro-sim"
    sim.write_text("#!/bin/sh\n")
    sim.chmod(0o755)
    out = tmp_path / "out"
    out.mkdir()
    (out / "calibration.json").write_text("an earlier run's")
    code = tool.main(["--sim", "--out", str(out), "--gyro-sim", str(sim)])
    assert code == (0 if passed else tool.EXIT_VERIFY_FAILED)
    assert (out / "calibration.json").exists() == passed
    assert (out / "calibration_unverified.json").exists() == (not passed)
    kept = out / ("calibration.json" if passed else "calibration_unverified.json")
    assert paramset.read(str(kept)).values()["cal.ref_freq_hz"] == pytest.approx(1489.9)


def test_a_value_out_of_the_firmwares_range_is_a_failed_stage(tmp_path, monkeypatch):
    """A stage whose result the parameter set refuses (a vacuum part's thermometer span,
    2140 deg, beyond rate.p_range_deg's 180) is a failed stage, exit 1, not a usage
    error (it once exited 2)."""
    from gyrotools.errors import InputError

    tool = load_tool()
    monkeypatch.setattr(calflow, "selfcal", lambda part: ("x", {"f0_hz": 1489.9, "q": 33.0}))

    def refused(part, path):
        raise InputError("rate.p_range_deg: 2140.6 out of range [0, 180]")

    monkeypatch.setattr(calflow, "rate_table", refused)
    sim = tmp_path / "gyro-sim"
    sim.write_text("#!/bin/sh\n")
    sim.chmod(0o755)
    out = tmp_path / "out"
    code = tool.main(["--sim", "--out", str(out), "--gyro-sim", str(sim)])
    assert code == tool.EXIT_STAGE_FAILED
    assert not (out / "calibration.json").exists()


# --drive: the sweep's choice (auto), or the mode asked for written into a copy of the
# self-calibration's set; the fixed drive is refused beyond its reach.
CAL = os.path.join(os.path.dirname(__file__), "..", "..", "..", "host_sim", "parts",
                   "default", "calibration.json")


def test_choose_drive(tmp_path):
    part = calflow.SimPart("sim", "scen", [], 1, str(tmp_path))
    assert calflow.choose_drive(part, CAL, "auto", 33.0) == CAL
    tracked = calflow.choose_drive(part, CAL, "tracking", 33.0)
    assert paramset.read(tracked).values()["drive.track"] == 1
    assert paramset.read(CAL).values()["drive.track"] == 0  # the original untouched
    fixed = calflow.choose_drive(part, tracked, "fixed", 4000.0)
    assert paramset.read(fixed).values()["drive.track"] == 0
    with pytest.raises(calflow.FlowError, match="beyond the fixed drive"):
        calflow.choose_drive(part, CAL, "fixed", 2.0e4)
    with pytest.raises(calflow.FlowError, match="one of"):
        calflow.choose_drive(part, CAL, "pll", 33.0)


def test_startup_lead(tmp_path):
    """The verification schedule waits for a high-Q part's start-up (4 drive time
    constants and a margin beyond the schedule's own first 7 s at rest), and not at all
    for the air part."""
    assert calflow.startup_lead_s(CAL) == 0.0
    ps = paramset.read(CAL)
    v = ps.values()
    v["drive.cal_q"] = 33330.0
    v["drive.cal_f0_hz"] = 1499.24
    path = str(tmp_path / "q.json")
    paramset.write(path, paramset.from_values(v, meta=ps.meta))
    tau = 2 * 33330.0 / (2 * 3.141592653589793 * 1499.24)  # 7.08 s
    lead = calflow.startup_lead_s(path)
    assert lead == float(int(4 * tau + 2.0 - 7.0) + 1) and lead > 20.0


def test_dwell_mask_leaves_out_the_start_up():
    """With a lead, the verification's first held window (lead + the schedule's first
    rests, at 0) is the start-up and not judged; without one, the schedule is judged as
    before. Failed so on four parts of the vacuum lot before (the window was judged)."""
    lead = 20.0
    steps = [[lead, 0]] + calflow.lincal.table_steps((30, -30), 10.0, calflow.VERIFY_REST_S)
    t = np.arange(0.0, sum(s[0] for s in steps), 0.005)
    edges = np.cumsum([0.0] + [s[0] for s in steps])
    truth = np.array([steps[np.searchsorted(edges, x, side="right") - 1][1] for x in t], float)
    m = calflow.dwell_mask(t, truth, t[-1], lead)
    assert not m[t < lead + 7.0].any() and m[(t > 40.0) & (t < 41.0)].all()
    m0 = calflow.dwell_mask(t, truth, t[-1], 0.0)
    assert m0[(t > 10.0) & (t < 20.0)].any()


def test_locked_log():
    """The rate table is judged from where the drive stays LOCKED: an air part's log
    (LOCKED at 0.04 s) whole, a part locking at 3 s from there, one that locks only in
    the second half of the run refused."""
    t = np.arange(0.0, 26.0, 0.005)

    def log(t_lock):
        d = np.zeros(t.size, dtype=[("t_s", float), ("rate_invalid", float), ("x", float)])
        d["t_s"], d["rate_invalid"], d["x"] = t, np.where(t < t_lock, 1.0, 0.0), t * 2
        return csvlog.Log("log.csv", d, ("t_s", "rate_invalid", "x"))
    air = log(0.04)
    assert calflow.locked_log(air, "x") is air
    late = calflow.locked_log(log(3.0), "x")
    assert late["t_s"][0] == pytest.approx(3.0) and late["x"][0] == pytest.approx(6.0)
    with pytest.raises(calflow.FlowError, match="not LOCKED"):
        calflow.locked_log(log(14.0), "rate table pass 0")


def _fake_sim(tmp_path):
    sim = tmp_path / "gyro-sim"
    sim.write_text("#!/bin/sh\n")
    sim.chmod(0o755)
    return str(sim)


@pytest.mark.parametrize("passed", [True, False])
def test_verify_only_judges_a_given_calibration_and_leaves_it(tmp_path, monkeypatch, passed):
    """--verify-only: no stage runs, the given set is verified as it is (never rewritten,
    never copied as calibration.json), the verdict is the exit code and report.json."""
    tool = load_tool()
    cal = os.path.join(os.path.dirname(TOOL), "..", "host_sim", "parts", "default",
                       "calibration.json")
    before = open(cal, "rb").read()
    seen = []

    def no_stage(*a, **k):
        raise AssertionError("a calibration stage ran under --verify-only")
    for stage in ("selfcal", "rate_table", "linearity", "thermal", "selftest"):
        monkeypatch.setattr(calflow, stage, no_stage)
    monkeypatch.setattr(calflow, "verify_all",
                        lambda part, path: seen.append(path) or {"stub": {"ok": passed}})
    monkeypatch.setattr(tool, "summarise", lambda res: None)
    out = tmp_path / "out"
    code = tool.main(["--sim", "--verify-only", cal, "--out", str(out),
                      "--gyro-sim", _fake_sim(tmp_path)])
    assert code == (0 if passed else tool.EXIT_VERIFY_FAILED)
    assert seen == [cal]
    assert open(cal, "rb").read() == before
    assert not (out / "calibration.json").exists()
    assert not (out / "calibration_unverified.json").exists()
    rep = json.load(open(out / "report.json"))
    assert rep["verify_only"] == cal and rep["verify"] == {"stub": {"ok": passed}}


@pytest.mark.parametrize("content", ["", "{}", "not json", '{"format": "gyro-param-set"}'])
def test_verify_only_refuses_what_is_not_a_param_set(tmp_path, monkeypatch, content):
    tool = load_tool()
    monkeypatch.setattr(calflow, "verify_all", lambda part, path: pytest.fail("verified"))
    bad = tmp_path / "bad.json"
    bad.write_text(content)
    out = tmp_path / "out"
    with pytest.raises(paramset.ParamSetError, match="bad.json"):
        tool.main(["--sim", "--verify-only", str(bad), "--out", str(out),
                   "--gyro-sim", _fake_sim(tmp_path)])
    assert not out.exists()


def test_verify_only_a_calibration_the_part_cannot_run_fails_the_verification(tmp_path,
                                                                               monkeypatch):
    """Another part's calibration on this part (the default set on the 1300 Hz part): the
    drive never locks, the verification's runs cannot be judged. That is a verification
    the set failed (exit 3, report.json says why), not a stage of the flow that broke."""
    tool = load_tool()
    cal = os.path.join(os.path.dirname(TOOL), "..", "host_sim", "parts", "default",
                       "calibration.json")

    def no_lock(part, path):
        raise calflow.FlowError("verify: the drive was not LOCKED for good before 50% of the run")
    monkeypatch.setattr(calflow, "verify_all", no_lock)
    out = tmp_path / "out"
    code = tool.main(["--sim", "--verify-only", cal, "--out", str(out),
                      "--gyro-sim", _fake_sim(tmp_path)])
    assert code == tool.EXIT_VERIFY_FAILED
    rep = json.load(open(out / "report.json"))
    assert rep["verify"]["passed"] is False and "LOCKED" in rep["verify"]["could_not_run"]


def test_recorded_commands_are_relative_below_the_run_folder(tmp_path, monkeypatch):
    """The report's stage commands name the simulator as the flow's own command line is
    written (the committed report.json had this machine's absolute build path in each)."""
    sim = tmp_path / "build" / "host-release" / "host_sim" / "gyro-sim"
    monkeypatch.chdir(tmp_path)
    assert calflow.shown_path(str(sim)) == os.path.join("build", "host-release", "host_sim",
                                                        "gyro-sim")
    outside = tmp_path.parent / "elsewhere" / "gyro-sim"
    assert calflow.shown_path(str(outside)) == str(outside)
