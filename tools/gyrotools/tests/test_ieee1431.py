"""ieee1431: the IEEE 1431 report's figures from synthetic verification logs of known
turn-on time, scale factor, nonlinearity, asymmetry, white noise and plateau bias law;
and a missing or garbled log named with the reason, the rest still written, the
calibration's verdict kept.

Tolerances are derived in the comments from the synthetic noise (about 4 standard
errors of each estimate), so that a wrong definition or a lost correction fails."""
import json
import math
import os
import shutil

import numpy as np
import pytest
import synth

from gyrotools import calflow, csvlog, ieee1431, lincal, thermcal
from gyrotools import ieee1431_figures as figures
from gyrotools import plotting as _plotting  # noqa: F401  (matplotlib's import: once, at collection)
from gyrotools.errors import InputError

SELFTEST = figures.SELFTEST_BIT
MODE = 1


def mklog(path="synthetic.csv", **cols):
    """An in-memory log (csvlog.Log) of the given columns."""
    n = len(next(iter(cols.values())))
    data = np.zeros(n, dtype=[(c, float) for c in cols])
    for c, v in cols.items():
        data[c] = v
    return csvlog.Log(path, data, tuple(cols))


def from_steps(t, steps):
    """A piecewise-constant profile [[duration, value], ...] at the times t."""
    edges = np.cumsum([0.0] + [d for d, _ in steps])
    k = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, len(steps) - 1)
    return np.array([v for _, v in steps], dtype=float)[k]


# --- 12.5 turn-on ---------------------------------------------------------------------

def turn_on_log(dt=0.005):
    """At rest for 2 s from power-on, then 30 deg/s. Valid for a moment at 0.20 s, then
    for good from 0.41 s; the output decays from 8 deg/s (below 1 deg/s at 0.125 s) but
    jumps 3 deg/s off at 0.300..0.310 s; a dropout at 2.5 s is after the rest."""
    t = np.arange(0.0, 3.0, dt)
    truth = np.where(t >= 2.0, 30.0, 0.0)
    valid = ((t >= 0.20) & (t < 0.25)) | (t >= 0.41)
    valid &= ~((t >= 2.5) & (t < 2.55))
    out = truth + 8.0 * np.exp(-t / 0.06) + 0.05 * np.random.default_rng(3).standard_normal(t.size)
    out[(t >= 0.300) & (t < 0.310)] += 3.0
    inval = np.where(valid, 0, 4) | np.where(t < 0.05, MODE, 0)
    return mklog(t_s=t, rate_dps=out, rate_true_dps=truth, rate_valid=valid.astype(float),
                 rate_invalid=inval)


def test_turn_on_time_is_valid_for_good_and_the_bound_after_the_last_excursion():
    f = figures.turn_on(turn_on_log(), 1.0)
    # The flag and the output change between samples: each time is the first sample at
    # or after the change, so exact to one sample (5 ms) at most.
    dt = 0.005
    assert f["turn_on_time_s"] == pytest.approx(0.41, abs=dt)          # not the 0.20 s blip
    assert f["first_valid_sample_s"] == pytest.approx(0.20, abs=dt)
    assert f["time_to_error_bound_s"] == pytest.approx(0.310, abs=dt)  # after the excursion
    assert f["rest_after_power_on_s"] == pytest.approx(2.0, abs=dt)    # the 2.5 s dropout is not in it
    assert f["drive_locked_s"] == pytest.approx(0.05, abs=dt)


def test_turn_on_never_valid_says_so():
    log = turn_on_log()
    log.data["rate_valid"][:] = 0.0
    f = figures.turn_on(log, 1.0)
    assert f["turn_on_time_s"] is None and "not valid for good" in f["turn_on_note"]


# --- 12.6 warm-up ---------------------------------------------------------------------

WARM_TAU_S, RAW_STEP_DPS, RAW_TAU_S = 15.0, -3.8, 300.0


def warmup_log(seconds=1800.0, dt=0.1, comp_end_dps=0.0, spike_dps=0.3, seed=11):
    """A cold start at rest: the raw output settles as RAW_STEP exp(-t/RAW_TAU) (within
    0.2 deg/s of its end from RAW_TAU ln(3.8/0.2) = 883 s), the compensated one as
    0.5 exp(-t/WARM_TAU) (within 0.2 from WARM_TAU ln 2.5 = 13.7 s) with a valid spike of
    spike_dps at 40..41 s and an invalid 2 deg/s one at 60..60.5 s; valid from 0.5 s."""
    t = np.arange(0.0, seconds, dt)
    rng = np.random.default_rng(seed)
    noise = 0.02 * rng.standard_normal(t.size)  # 1 s means: 0.006 deg/s sd
    raw = RAW_STEP_DPS * np.exp(-t / RAW_TAU_S) + noise
    comp = comp_end_dps + 0.5 * np.exp(-t / WARM_TAU_S) + noise
    comp[(t >= 40.0) & (t < 41.0)] += spike_dps
    bad = (t >= 60.0) & (t < 60.5)
    comp[bad] += 2.0
    valid = (t >= 0.5) & ~bad
    return mklog(t_s=t, rate_dps=comp, rate_unc_dps=raw, rate_true_dps=np.zeros_like(t),
                 rate_valid=valid.astype(float), rate_invalid=np.where(valid, 0, 4),
                 t_struct_c=25.0 + 1.3 * (1.0 - np.exp(-t / 400.0)))


def test_warm_up_time_is_after_the_last_valid_excursion_and_the_raw_settling_is_timed():
    f = thermcal.verify_warmup(warmup_log())
    # The 0.3 deg/s spike fills the 40 s bin: warm from the next bin. The invalid 2 deg/s
    # one is not the product's output (the rate says it is not valid): the 60 s bin is the
    # mean of its valid half.
    assert f["warmup_time_s"] == 41.0
    # 883 s: a 1 s bin straddling the crossing moves it by under a bin; the noise of the
    # means (0.006 deg/s sd) against the curve's slope there (0.2/300 deg/s per s) by about
    # 4 sd = 36 s.
    assert f["raw_settle_time_s"] == pytest.approx(RAW_TAU_S * math.log(3.8 / 0.2), abs=40.0)
    assert f["raw_change_dps"] == pytest.approx(3.8 * math.exp(-10.0 / RAW_TAU_S), abs=0.05)
    assert f["worst_valid_1s_dps"] == pytest.approx(0.5 * math.exp(-0.5 / WARM_TAU_S), abs=0.05)
    assert f["valid_fraction"] == pytest.approx(1.0 - 0.5 / 1799.5, abs=1e-4)
    assert f["ok"]


def test_warm_up_without_the_spike_is_the_decay_crossing_the_bound():
    f = thermcal.verify_warmup(warmup_log(spike_dps=0.0))
    assert f["warmup_time_s"] == pytest.approx(WARM_TAU_S * math.log(2.5), abs=1.0)


def test_warm_up_fails_when_the_output_ends_off_or_a_valid_mean_is_wrong():
    off = thermcal.verify_warmup(warmup_log(comp_end_dps=0.25))
    assert off["warmup_time_s"] is None and not off["ok"]
    wrong = thermcal.verify_warmup(warmup_log(spike_dps=1.5))
    assert wrong["worst_valid_1s_dps"] > 1.0 and not wrong["ok"]
    assert wrong["warmup_time_s"] == 41.0  # warm after it all the same
    log = warmup_log()
    log.data["rate_valid"][(log["t_s"] >= 100.0) & (log["t_s"] < 101.0)] = 0.0
    # A whole second the product does not stand behind is not warm.
    assert thermcal.verify_warmup(log)["warmup_time_s"] == 101.0


def test_warm_up_on_averaged_output_is_not_moved_by_a_late_one_second_excursion():
    # A settled part's 1 s means scatter (0.03..0.05 deg/s sd on the default part, and the
    # thermometer's phase flicker wanders the compensation by as much again): one of them
    # beyond the bound late in the run moves the 1 s figure there (the same part read
    # 31..566 s over ten noise seeds). The mean over the preceding WARMUP_AVG_S (10 s)
    # is the warm-up's: 0.5 exp(-t/15) averaged over 10 s, 0.711 exp(-t/15), crosses
    # 0.2 deg/s at 15 ln 3.55 = 19.0 s, whatever one second does at 1500 s.
    log = warmup_log()
    late = (log["t_s"] >= 1500.0) & (log["t_s"] < 1501.0)
    log.data["rate_dps"][late] += 0.3
    f = thermcal.verify_warmup(log)
    assert f["warmup_time_s"] == 1501.0  # the 1 s figure, as defined (IEEE 1431 12.6)
    assert f["warmup_avg_s"] == thermcal.WARMUP_AVG_S == 10.0
    assert f["warmup_time_avg_s"] == pytest.approx(15.0 * math.log(0.7108 / 0.2), abs=1.5)
    assert f["ok"]
    # An output that ends off is not warm on either figure.
    off = thermcal.verify_warmup(warmup_log(comp_end_dps=0.25))
    assert off["warmup_time_avg_s"] is None


def test_a_raw_output_still_moving_at_the_end_has_no_settling_time():
    # 600 s: the raw output moves 3.8 exp(-540/300) (1 - exp(-60/300)) = 0.11 deg/s
    # between its last two minutes, over a quarter of the 0.2 deg/s bound.
    f = thermcal.verify_warmup(warmup_log(seconds=600.0))
    assert f["raw_settle_time_s"] is None and not f["raw_settled_in_run"]
    assert f["raw_end_drift_dps_per_min"] == pytest.approx(0.11, abs=0.02)
    assert f["warmup_time_s"] == 41.0 and f["ok"]


def test_a_too_short_warm_up_log_is_an_input_error():
    with pytest.raises(InputError, match="too short for a warm-up time"):
        thermcal.verify_warmup(warmup_log(seconds=100.0))


# --- 12.9 scale factor ----------------------------------------------------------------

DWELL, REST, FS_TABLE = 2.0, 1.5, 200.0
SIGMA = 0.05       # deg/s per sample, white
DRIFT = 0.02       # deg/s per s: the bias's wander, taken out against the rests
B0 = 0.3


def table_log(s_pos, s_neg, c3, seed=5):
    """The verification's rates (+-30..270), shorter dwells, then a 1 s self-test of
    +5.5 deg/s at rest, which the series must leave out."""
    steps = lincal.table_steps(calflow.VERIFY_RATES_DPS, DWELL, REST) + [[1.0, 0]]
    t = np.arange(0.0, sum(d for d, _ in steps), 1.0 / FS_TABLE)
    r = from_steps(t, steps)
    test = t >= t[-1] + 1.0 / FS_TABLE - 1.0
    y = B0 + DRIFT * t + np.where(r >= 0, s_pos, s_neg) * r + c3 * r ** 3
    y += SIGMA * np.random.default_rng(seed).standard_normal(t.size) + np.where(test, 5.5, 0.0)
    return mklog(t_s=t, rate_dps=y, rate_true_dps=r, rate_valid=np.ones(t.size),
                 rate_invalid=np.where(test, SELFTEST, 0)), steps


# Noise of a held mean, each rate against the two rests around it: the rate's 1.5 s
# (300 samples) and half of each 1.0 s rest's (200): SIGMA sqrt(1/300 + 1/400).
SIGMA_EFF = SIGMA * math.sqrt(1 / 300 + 1 / 400)
X = np.array(calflow.VERIFY_RATES_DPS, dtype=float)


def rest_centres(steps):
    """Mid-times of the judged rest windows (after the 0.5 s settling), from the schedule:
    the 2 s lead and the first rest are one window."""
    ends = np.cumsum([d for d, _ in steps])
    starts = ends - [d for d, _ in steps]
    c = [(starts[k] + calflow.SETTLE_S + ends[k]) / 2 for k in range(len(steps))
         if steps[k][1] == 0 and k not in (0, len(steps) - 1)]
    c[0] = (0.0 + calflow.SETTLE_S + ends[1]) / 2
    return np.array(c)


def test_scale_factor_bias_and_cubic_nonlinearity():
    s, c3 = 1.0008, 1.0e-8
    log, steps = table_log(s, s, c3)
    res, f = figures.scale_factor(log)
    # Least squares over symmetric rates: the slope of s x + c3 x^3 is s + c3 sum(x^4)/sum(x^2); its standard error
    # SIGMA_EFF / sqrt(sum(x^2)) = 6e-6. The drift, 1 deg/s over the run, would move it
    # by -180 ppm if the rates were not referred to their rests.
    k = np.sum(X ** 4) / np.sum(X ** 2)
    se = SIGMA_EFF / math.sqrt(np.sum(X ** 2))
    assert f["scale_factor_dps_per_dps"] == pytest.approx(s + c3 * k, abs=4 * se)
    # The bias is the rests' level: B0 + DRIFT at their mean time. Its error: the mean of
    # 15 rests of 200 samples, and the 14 rates' SIGMA_EFF averaged.
    se_b = math.hypot(SIGMA / math.sqrt(200 * 15), SIGMA_EFF / math.sqrt(14))
    assert f["bias_dps"] == pytest.approx(B0 + DRIFT * rest_centres(steps).mean(), abs=4 * se_b)
    # Nonlinearity: the cubic's input-referred residuals over the 14 rates (the rests,
    # which carry the drift, stay out), RMS / 270 deg/s. The noise moves an RMS by at
    # most the RMS of the noise (triangle inequality), about SIGMA_EFF: 4 of it.
    resid = c3 * (X ** 3 - k * X) / (s + c3 * k)
    nl = 100 * math.sqrt(np.mean(resid ** 2)) / 270.0
    assert f["nonlinearity_rms_percent_fs"] == pytest.approx(nl, abs=100 * 4 * SIGMA_EFF / 270)
    assert nl > 100 * 8 * SIGMA_EFF / 270  # the cubic is well above that tolerance
    assert len(f["held_means"]) == 14 and len(f["rests"]) == 15  # not the self-test's 5.5
    assert abs(f["asymmetry_ppm"]) < 100


def test_asymmetry():
    s_pos, s_neg = 1.001, 0.999
    log, _ = table_log(s_pos, s_neg, 0.0, seed=6)
    _, f = figures.scale_factor(log)
    # Each side's slope (its 7 rates) has the standard error
    # SIGMA_EFF / sqrt(sum((x - mean)^2)) = 2e-5; the asymmetry sqrt(2) of that relative.
    pos = X[X > 0]
    se = math.sqrt(2) * SIGMA_EFF / math.sqrt(np.sum((pos - pos.mean()) ** 2))
    assert f["asymmetry_ppm"] == pytest.approx((s_pos - s_neg) / 1.0 * 1e6, abs=4 * se * 1e6)
    # The slope over all rates is the mean of the two sides'.
    assert f["scale_factor_dps_per_dps"] == pytest.approx(1.0, abs=4 * SIGMA_EFF / math.sqrt(np.sum(X ** 2)))


# --- 12.11 drift: Allan white noise ---------------------------------------------------

def noise_log(n_comp, n_unc, fs=100.0, seconds=150.0, seed=7):
    n = int(seconds * fs)
    rng = np.random.default_rng(seed)
    return mklog(t_s=np.arange(n) / fs, rate_dps=synth.white_dps(n, fs, n_comp, rng),
                 rate_unc_dps=synth.white_dps(n, fs, n_unc, rng))


def test_drift_recovers_the_white_noise_level():
    n_c, n_u = 30.0, 20.0  # deg/h/rtHz
    f, _, means = figures.drift(noise_log(n_c, n_u))
    # test_allan measured N's scatter at 0.13 % (std) on 2^18 samples; this record has
    # 12000 (from 30 s on), sqrt(2^18/12000) = 4.7x fewer degrees of freedom: 0.6 %, 4 of
    # it 2.4 %, so 3 %.
    assert f["rate_dps"]["ieee952"]["N"]["value"] == pytest.approx(n_c / 60.0, rel=0.03)
    assert f["rate_unc_dps"]["ieee952"]["N"]["value"] == pytest.approx(n_u / 60.0, rel=0.03)
    assert f["rate_dps"]["ieee952"]["N"]["unit"] == "deg/sqrt(h)"
    # The 1 s means of white noise: N / sqrt(1 s) deg/h; their sample std over 120 means
    # scatters 1/sqrt(2 x 119) = 6.5 % relative: 4 of it 26 %.
    assert f["rate_dps"]["means_1s_std_dps"] == pytest.approx(n_c / 3600.0, rel=0.26)
    assert means["t_s"][0] >= thermcal.START_S and means["rate_dps"].size == 120


# --- 12.8 temperature: plateau bias law and the ramp ----------------------------------

PROTO = thermcal.QUICK
B1, SF1 = 0.015, 40e-6      # deg/s per K and 1/K of structure temperature
SIGMA_T = 0.02              # deg/s per sample at 10 Hz


def t_struct(amb):
    """A structure that has not reached the chamber (0.6 of the way), as the quick
    protocol's short plateaus."""
    return 25.0 + 0.6 * (np.asarray(amb) - 25.0)


def plateau_log(seed=8):
    amb_steps, rate_steps, dur = thermcal._plateau_profiles(PROTO.verify_plateaus_c, PROTO.dwell_s)
    t = np.arange(0.0, dur, 0.1)
    ts = t_struct(from_steps(t, amb_steps))
    r = from_steps(t, rate_steps)
    y = 0.02 + B1 * (ts - 25) + (1 + SF1 * (ts - 25)) * r
    y += SIGMA_T * np.random.default_rng(seed).standard_normal(t.size)
    return mklog(t_s=t, rate_dps=y, rate_true_dps=r, rate_valid=np.ones(t.size),
                 p_f_deg=25 + 0.08 * (ts - 25), t_struct_c=ts)


def test_plateaus_recover_the_bias_and_scale_factor_law():
    rows = figures.plateaus(plateau_log(), PROTO)["plateaus"]
    # Bias: the mean of 100 s at 10 Hz (1000 samples): SE 0.0006 deg/s. Scale factor:
    # (u(+R) - u(-R)) / 2R from 2 x 450 and 450 samples: SE
    # SIGMA_T sqrt(1/900 + 1/450) / 200 = 5.8 ppm.
    se_b = SIGMA_T / math.sqrt(1000)
    se_sf = SIGMA_T * math.sqrt(1 / 900 + 1 / 450) / 200 * 1e6
    for amb, r in zip(PROTO.verify_plateaus_c, rows):
        ts = t_struct(amb)
        assert r["ambient_c"] == amb and r["t_struct_c"] == pytest.approx(ts)
        assert r["bias_dps"] == pytest.approx(0.02 + B1 * (ts - 25), abs=4 * se_b)
        assert r["scale_factor_error_ppm"] == pytest.approx(SF1 * (ts - 25) * 1e6, abs=4 * se_sf)


def test_a_plateau_log_without_structure_temperature_reports_null(tmp_path):
    log = plateau_log()
    cols = {c: log[c] for c in log.data.dtype.names if c != "t_struct_c"}
    rows = figures.plateaus(mklog(**cols), PROTO)["plateaus"]
    assert all(math.isnan(r["t_struct_c"]) for r in rows)
    from gyrotools import cli
    doc = json.loads(open(cli.write_json(str(tmp_path), "x.json", {"rows": rows})).read())
    assert doc["rows"][0]["t_struct_c"] is None and doc["rows"][0]["bias_dps"] is not None


def ramp_log(seed=9, with_struct=True):
    t_from, t_to, k_per_min, lead, tail = PROTO.ramp
    dur = lead + (t_to - t_from) / k_per_min * 60 + tail
    t = np.arange(0.0, dur, 0.1)
    amb = t_from + k_per_min / 60 * np.clip(t - lead, 0, (t_to - t_from) / k_per_min * 60)
    y = B1 * (t_struct(amb) - 25) + SIGMA_T * np.random.default_rng(seed).standard_normal(t.size)
    cols = dict(t_s=t, rate_dps=y, rate_true_dps=np.zeros(t.size), rate_valid=np.ones(t.size),
                t_ambient_c=amb)
    if with_struct:
        cols["t_struct_c"] = t_struct(amb)
    return mklog(**cols)


def test_ramp_bias_slope_against_the_structure():
    f = figures.ramp(ramp_log(), PROTO)
    # The slope of 1 s means (SE SIGMA_T / sqrt(10) each) against the known structure
    # temperatures of the bins: SE sigma / sqrt(sum((T - mean)^2)).
    ts = f["means_1s"]["t_struct_c"]
    se = SIGMA_T / math.sqrt(10) / math.sqrt(np.sum((ts - ts.mean()) ** 2))
    assert f["bias_slope_dps_per_k_of_struct"] == pytest.approx(B1, abs=4 * se)
    # Without a structure temperature, against the ambient: 0.6 x the law per K of it.
    g = figures.ramp(ramp_log(with_struct=False), PROTO)
    assert g["bias_slope_dps_per_k_of_ambient"] == pytest.approx(0.6 * B1, abs=4 * se)


# --- the report folder, and what a missing or garbled log does -------------------------

def _write(path, log, every=1):
    """The log as gyro-sim's CSV (synth fills the other standard columns with 0), every
    n-th row: the folder's tests check the layout, the figures' tests the accuracy."""
    synth.write_log(str(path), {c: log[c][::every] for c in log.data.dtype.names})


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """A DIR as tools/calibrate --quick leaves it, with short synthetic logs."""
    d = tmp_path_factory.mktemp("cal")
    work = d / "work"
    work.mkdir()
    log, _ = table_log(1.0, 1.0, 0.0)
    _write(work / "verify.csv", log, every=4)          # 50 Hz is enough for the layout
    _write(work / "verify_noise.csv", noise_log(30.0, 20.0, seconds=45.0))
    _write(work / "verify_plateaus.csv", plateau_log(), every=10)
    _write(work / "verify_ramp.csv", ramp_log(), every=5)
    _write(work / "verify_warmup.csv", warmup_log(seconds=600.0), every=2)
    run = {k: {"command": f"gyro-sim --seed {1001 + i}", "seed": 1001 + i}
           for i, k in enumerate(("rate", "thermal_plateaus", "thermal_ramp", "noise", "warmup"))}
    run["rate"]["limits"] = {"worst_valid_error_dps": 1.0}
    (d / "report.json").write_text(json.dumps({
        "tool": "calibrate", "command": "tools/calibrate --sim --quick --verify-only X --out D",
        "part": {"set": ["plant.q_drive=40"]}, "seed": 1, "protocol": "quick",
        "verify_only": "X", "verify": run}))
    return d


def copy(made, tmp_path):
    d = tmp_path / "dir"
    shutil.copytree(made, d)
    return d


@pytest.fixture(scope="module")
def written(made, tmp_path_factory):
    """The report of the whole synthetic folder, written once for the tests below (four
    figures cost about 1.8 s of CPU, most of it matplotlib's layout and rendering)."""
    d = tmp_path_factory.mktemp("written") / "dir"
    shutil.copytree(made, d)
    path, doc, problems = ieee1431.write(str(d))
    return d, path, doc, problems


def test_report_folder_holds_every_series(written):
    d, path, doc, problems = written
    assert problems == []
    folder = d / "ieee1431"
    assert path == str(folder / "ieee1431.json")
    for name in ("turn_on", "warm_up", "scale_factor", "drift", "temperature"):
        assert (folder / doc[name]["png"]).is_file()
        assert not os.path.isabs(doc[name]["png"])
    assert ieee1431.pngs(doc) == ["turn_on.png", "warm_up.png", "scale_factor.png", "drift.png",
                                  "temperature.png"]


def test_report_json_names_each_runs_command_seed_and_log(written):
    _, _, doc, _ = written
    assert doc["turn_on"]["log"] == os.path.join("..", "work", "verify.csv")
    assert doc["drift"]["seed"] == 1004 and doc["drift"]["command"] == "gyro-sim --seed 1004"
    assert doc["temperature"]["ramp"]["seed"] == 1003
    assert doc["temperature"]["plateaus"]["seed"] == 1002
    assert doc["warm_up"]["seed"] == 1005 and doc["warm_up"]["warmup_time_s"] == 41.0
    assert doc["part"] == "part plant.q_drive=40" and doc["report"] == os.path.join("..", "report.json")


def test_report_json_writes_what_is_not_measured_as_null(written):
    d, _, _, _ = written
    text = (d / "ieee1431" / "ieee1431.json").read_text()
    assert "NaN" not in text and "Infinity" not in text
    k = json.loads(text)["drift"]["rate_dps"]["ieee952"]["K"]
    assert k["value"] is None and k["source"].startswith("not observable")


def test_missing_and_garbled_logs_are_named_and_the_rest_written(made, tmp_path):
    d = copy(made, tmp_path)
    (d / "work" / "verify_noise.csv").unlink()
    (d / "work" / "verify_ramp.csv").write_text("t_s,rate_dps\n0,1\n0.1,abc\n")
    (d / "ieee1431").mkdir()
    (d / "ieee1431" / "drift.png").write_text("an earlier run's")
    _, doc, problems = ieee1431.write(str(d))
    assert any("verify_noise.csv" in p and "cannot open" in p for p in problems)
    assert any("verify_ramp.csv" in p for p in problems)
    assert "error" in doc["drift"] and not (d / "ieee1431" / "drift.png").exists()
    assert "error" in doc["temperature"]["ramp"] and "error" not in doc["temperature"]["plateaus"]
    assert (d / "ieee1431" / "temperature.png").is_file()
    assert (d / "ieee1431" / "scale_factor.png").is_file()


def test_a_report_json_that_is_no_calibrations_is_refused(tmp_path):
    with pytest.raises(InputError, match="cannot open"):
        ieee1431.write(str(tmp_path))
    (tmp_path / "report.json").write_text("{ not json")
    with pytest.raises(InputError, match="not JSON"):
        ieee1431.write(str(tmp_path))
    (tmp_path / "report.json").write_text('{"tool": "lot"}')
    with pytest.raises(InputError, match="verify"):
        ieee1431.write(str(tmp_path))


def test_a_too_short_noise_log_is_an_input_error():
    with pytest.raises(InputError, match="after the start-up"):
        figures.drift(noise_log(30.0, 20.0, seconds=31.0))


# --- tools/calibrate: the report never changes the verdict ----------------------------

CAL = os.path.join(os.path.dirname(__file__), "..", "..", "..", "host_sim", "parts",
                   "default", "calibration.json")


def _verify_only(tmp_path, monkeypatch, capsys):
    """tools/calibrate --verify-only with the verification's runs replaced by a passing
    double that leaves no logs: (exit status, stdout, stderr)."""
    from test_calibrate_outputs import load_tool
    tool = load_tool()
    monkeypatch.setattr(calflow, "verify_all", lambda part, cal: {"rate": {"passed": True}})
    monkeypatch.setattr(tool, "summarise", lambda res: None)
    sim = tmp_path / "gyro-sim"
    sim.write_text("#!/bin/sh\n")
    sim.chmod(0o755)
    code = tool.main(["--sim", "--quick", "--verify-only", CAL, "--out", str(tmp_path / "out"),
                      "--gyro-sim", str(sim)])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_calibrate_names_each_missing_log_and_keeps_the_verdict(tmp_path, monkeypatch, capsys):
    code, out, err = _verify_only(tmp_path, monkeypatch, capsys)
    assert code == 0 and "Traceback" not in err
    for name in ("verify.csv", "verify_noise.csv", "verify_plateaus.csv", "verify_ramp.csv",
                 "verify_warmup.csv"):
        assert any(name in ln and "cannot open" in ln and "WARNING" in ln
                   for ln in err.splitlines()), name
    assert "IEEE 1431 report: wrote" in out and "ieee1431.json" in out


def test_calibrate_keeps_the_verdict_when_the_report_itself_fails(tmp_path, monkeypatch, capsys):
    def broken(out, cal):
        raise RuntimeError("a fault of the report")
    monkeypatch.setattr(ieee1431, "write", broken)
    code, _, err = _verify_only(tmp_path, monkeypatch, capsys)
    assert code == 0
    assert "a fault of the report" in err and "the verdict stands" in err
