"""tools/fr-noise and its library: bad options are refused (exit 2, nothing run); the
read-offs are right on constructed records (N of a white rate noise, the scale factor of
the steps, the nulling's check); the force-rebalance part's model puts f0 at the
resonance the loop sees (the DC bias's softening taken off, as
tests/closed_loop/test_cl_sense_fr.c does); --quad-null gives the part its nulling
electrodes, their noise off, and the firmware quad.null 1."""

import math
import os

import numpy as np
import pytest

from gyrotools import frnoise, frpart
from gyrotools.errors import InputError

DEFAULT_CAL = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..",
                           "host_sim", "parts", "default", "calibration.json")


@pytest.mark.parametrize("args, why", [
    (["--schemes", "half,x"], "--schemes"),
    (["--ft", "maybe"], "--ft"),
    (["--duration", "10"], "--duration"),
    (["--q-sense", "0.1"], "--q-sense"),
    (["--gyro-sim", "/nonexistent/gyro-sim"], "not an executable"),
    (["--cal", DEFAULT_CAL, "--schemes", "half"],
     "not a calibration of this case's configuration"),
    (["--cal", DEFAULT_CAL], "one --schemes"),
    (["--cal", "/nonexistent/cal.json", "--schemes", "half"], "cal.json"),
])
def test_bad_options_refused(run_script, tmp_path, args, why):
    code, out, err = run_script("fr-noise", args + ["--out", str(tmp_path / "o")])
    assert code == 2 and why in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_arw_of_white_noise():
    """A white rate noise of N deg/h/rtHz (two-sided) at 100 Hz reads back within 5 %."""
    n_dph = 7.0
    fs = frnoise.AVG_RATE_HZ
    rng = np.random.default_rng(1)
    x = rng.standard_normal(200000) * n_dph / 3600.0 * math.sqrt(fs)
    tau, ad = frnoise.adev(x, fs, np.logspace(-2, 2, 21))
    assert abs(frnoise.arw_coeff(tau, ad) / n_dph - 1.0) < 0.05
    assert frnoise.at_tau(tau, ad, 1000.0) is None
    assert abs(frnoise.at_tau(tau, ad, 10.0) / (n_dph / math.sqrt(10.0)) - 1.0) < 0.2


def test_scale_factor_of_the_steps():
    t = np.arange(0.0, 130.0, 0.01)
    true = np.where((t >= 100) & (t < 110), 100.0, np.where((t >= 110) & (t < 120), -100.0, 0.0))
    rate = 1.008 * true + 0.3
    assert frnoise.scale_factor(t, rate, true, 100.0) == pytest.approx(1.008, rel=1e-9)


def test_model_at_the_softened_resonance():
    """DC+AC with a 2 um gap: 4 Ks Vb^2 / gap = 5e6 1/s^2 takes 1639.10 Hz down to 1600 Hz; the
    half-frequency pair (fb_mode 3) has no DC and keeps its resonance."""
    p = {"f_sense_hz": 1639.1008, "q_sense": 1e4, "fb_mode": 2, "fb_gap_m": 2e-6,
         "ks_fb_mps2_per_v2": 0.1, "fb_bias_v": 5.0, "drive_amp_m": 1e-5,
         "pick_sense_gain_v_per_m": 6.18e7}
    assert frpart.softened_f_hz(p) == pytest.approx(1600.0, abs=0.01)
    assert frpart.softened_f_hz({**p, "fb_mode": 3}) == pytest.approx(1639.1008)
    cal = {"drive.freq_hz": 1489.86, "rate.scale_dps": 100.0, "rate.demod_phase_deg": 60.0,
           "drive.amp_set_v": 0.35}
    base = {**p, "f_sense_hz": 2000.0, "q_sense": 3.0}
    fw = frpart.model_values(cal, base, p)
    assert fw["sense.f0_hz"] == pytest.approx(1600.0, abs=0.01)
    # the scale moves with the mode's gain at the drive frequency, (2-24)
    wc = 2 * math.pi * 1489.86
    m0, _ = frpart.mode_response(2000.0, 3.0, wc)
    m1, _ = frpart.mode_response(1600.0, 1e4, wc)
    assert fw["rate.scale_dps"] == pytest.approx(100.0 * m0 / m1, rel=1e-6)


def test_matched_part_staged_on_the_drive():
    """--matched: the tuning calibration a sweep stages puts the sense resonance on the
    calibration's drive frequency within half of one DAC code's move; the voltage is a
    code's; the model's mode is that tuned resonance, its Q lowered with it (the damping
    stays)."""
    p = {"f_sense_hz": 1600.0, "q_sense": 1e4, "fb_mode": 3, "f_drive_hz": 1490.0,
         "tune_ke_per_s2_per_v2": frpart.TUNE_KE, "ks_fb_mps2_per_v2": 0.1,
         "drive_amp_m": 1e-5, "pick_sense_gain_v_per_m": 6.18e7}
    cal = {"drive.freq_hz": 1489.8561, "rate.scale_dps": 100.0, "rate.demod_phase_deg": 60.0,
           "drive.amp_set_v": 0.35}
    staged, f_t, q_t = frpart.matched_values(cal, p)
    s0 = 1600.0 * 1489.8561 / 1490.0
    assert staged["sense.tune"] == 1
    assert staged["sense.cal_s0_hz"] == pytest.approx(s0)
    assert staged["sense.cal_tune_ref_hz"] == 1489.8561
    assert staged["sense.cal_tune_ke_per_s2_per_v2"] == frpart.TUNE_KE
    v = staged["cal.ref_tune_v"]
    assert 7.0 < v < 8.0 and v / frpart.DAC_V_PER_CODE == pytest.approx(
        round(v / frpart.DAC_V_PER_CODE), abs=1e-9)
    # one code's move of the resonance: d f = ke v dv / (4 pi^2 f)
    code_hz = frpart.TUNE_KE * v * frpart.DAC_V_PER_CODE / (4 * math.pi ** 2 * f_t)
    assert abs(f_t - 1489.8561) <= 0.5 * code_hz + 1e-9
    assert q_t == pytest.approx(1e4 * f_t / s0)
    fw = frpart.model_values(cal, {**p, "q_sense": 3.0}, p, f_t, q_t)
    assert fw["sense.f0_hz"] == f_t and fw["sense.q"] == q_t
    with pytest.raises(ValueError):
        frpart.matched_values(cal, {**p, "f_sense_hz": 1450.0})
    with pytest.raises(ValueError):
        frpart.matched_values(cal, {**p, "tune_ke_per_s2_per_v2": 0.0})


def test_quad_null_part_and_firmware():
    """--quad-null: the plant gets test_cl_quadnull.c's 20 (deg/s)/V^2 electrodes with their
    voltage noise off (brownian_only's conditions), in both studies; without it the part has
    none; the firmware setting turns the nulling loop on."""
    defaults = {"fb_noise_white_v_rthz": 2e-7, "fb_noise_1hz_v_rthz": 2e-6,
                "fb_noise_fmin_hz": 1e-3}
    for study in ("brownian", "electrode"):
        p = frnoise.case_plant(study, False, defaults, quad_null=True)
        assert p["quadnull_dps_per_v2"] == 20.0 == frnoise.QN_DPS_PER_V2
        assert p["quadnull_noise_white_v_rthz"] == 0 and p["quadnull_noise_1hz_v_rthz"] == 0
    assert "quadnull_dps_per_v2" not in frnoise.case_plant("brownian", True, defaults)
    assert frnoise.QUAD_NULL_FW == ["--set", "firmware.quad.null=1",
                                    "--set", "firmware.cal.ref_quad_null=1"]


def test_quad_null_option_parsed(run_script, tmp_path):
    """--quad-null is an option of fr-noise (a bad value elsewhere still refuses the run)."""
    code, out, err = run_script("fr-noise", ["--quad-null", "--ft", "maybe",
                                             "--out", str(tmp_path / "o")])
    assert code == 2 and "--ft" in err and "unrecognized" not in err
    code, out, err = run_script("fr-noise", ["--quad-nul1", "--out", str(tmp_path / "o")])
    assert code == 2 and "unrecognized" in err
    assert not (tmp_path / "o").exists()


def _record(quad_true, valid, t_end=100.0):
    t = np.arange(0.0, t_end + 30.0, 0.01)
    return {"t_s": t, "rate_dps": np.zeros_like(t), "rate_true_dps": np.zeros_like(t),
            "quad_dps": 0.5 * quad_true(t), "quad_true_dps": quad_true(t),
            "rate_valid": valid(t).astype(float)}


def test_quadnull_check():
    """Nulled: within 1 deg/s and valid from 0.7 s, the analysis from 5 s; not nulled: the
    quadrature beyond 1 deg/s after the analysis's start, or the rate invalid there; after
    the record (the scale factor's steps) nothing counts."""
    def nulled(t):
        return np.where(t < 0.7, 1500.0, 0.3 * np.sin(t))

    def valid(t):
        return t >= 0.7

    r = frnoise.quadnull_check(_record(nulled, valid), 100.0, 5.0)
    assert r["nulled"] and r["nulled_and_valid_from_s"] == pytest.approx(0.7)
    assert r["quad_true_max_abs_dps"] <= 0.3 and r["rate_valid_fraction"] == 1.0
    assert r["quad_fw_std_dps"] == pytest.approx(0.5 * r["quad_true_std_dps"])
    late = frnoise.quadnull_check(_record(nulled, lambda t: t >= 6.0), 100.0, 5.0)
    assert not late["nulled"] and late["nulled_and_valid_from_s"] == pytest.approx(6.0)
    bump = frnoise.quadnull_check(
        _record(lambda t: np.where((t > 50) & (t < 50.5), 2.0, nulled(t)), valid), 100.0, 5.0)
    assert not bump["nulled"]
    after = frnoise.quadnull_check(
        _record(lambda t: np.where(t > 105, 2.0, nulled(t)), lambda t: (t >= 0.7) & (t < 110)),
        100.0, 5.0)
    assert after["nulled"]


def test_the_part_an_own_calibration_is_made_on_is_the_cases_without_noise():
    part = frnoise.calibration_part(q_sense=300.0, quad_null=True, scheme="dcac")
    assert part[0] == "plant.preset=ideal"
    assert "plant.q_sense=300" in part and "plant.fb_mode=2" in part
    assert "plant.quadnull_dps_per_v2=20" in part
    assert not any("noise" in s for s in part)


def test_an_own_calibration_of_another_configuration_is_refused():
    ok = {"sense.mode": 1, "sense.fb_scheme": 0, "quad.null": 1}
    frnoise.check_own_cal(ok, "half", True)
    for bad, scheme, qn in ((dict(ok, **{"sense.mode": 0}), "half", True),
                            (ok, "dcac", True), (ok, "half", False)):
        with pytest.raises(InputError, match="--cal"):
            frnoise.check_own_cal(bad, scheme, qn)
