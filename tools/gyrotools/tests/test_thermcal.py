"""thermcal's protocols: every judged window lies inside its plateau, and the quick
protocol's valid thermometer span is what its fit's data reached, not its unsettled
plateaus'."""

import numpy as np
import pytest

from gyrotools import thermcal


@pytest.mark.parametrize("proto", [thermcal.FULL, thermcal.QUICK], ids=lambda p: p.name)
def test_judged_windows_lie_inside_their_plateau(proto):
    _, rate, dur = thermcal._plateau_profiles(proto.cal_plateaus_c, proto.dwell_s)
    t = np.arange(0.0, dur, 0.1)
    for k in range(len(proto.cal_plateaus_c)):
        t0, t1 = k * proto.dwell_s + thermcal.CHAMBER_EDGE_S, (k + 1) * proto.dwell_s
        for w in thermcal.plateau_windows(t, k, proto.dwell_s):
            assert np.any(w)
            assert t[w].min() >= t0 and t[w].max() < t1


def test_rest_window_keeps_the_full_protocols_length():
    assert thermcal.rest_avg_s(thermcal.FULL.dwell_s) == thermcal.REST_AVG_S
    assert 0.0 < thermcal.rest_avg_s(thermcal.QUICK.dwell_s) < thermcal.REST_AVG_S


def _log(p_of_t, dur):
    t = np.arange(0.0, dur, 0.1)
    return {"t_s": t, "p_f_deg": p_of_t(t), "rate_true_dps": np.zeros_like(t)}


def test_span_from_data_covers_the_transients():
    # P overshoots the plateaus' means between them (a part whose plateaus are short).
    log = _log(lambda t: 25.0 + 0.5 * np.sin(2 * np.pi * t / 400.0), 1200.0)
    pts = [{"p_deg": 25.1}, {"p_deg": 24.9}]
    ref_pl, half_pl = thermcal.fitted_span(log, pts, False)
    ref_d, half_d = thermcal.fitted_span(log, pts, True)
    assert (ref_pl, half_pl) == pytest.approx((25.0, 0.1))
    assert ref_d == pytest.approx(25.0, abs=0.02)
    # P_c's low-passes (two of 25 s) trim the peaks: 0.5 / (1 + (w tau)^2)
    w_tau = 2 * np.pi / 400.0 * thermcal.COMP_TAU_S
    assert half_d == pytest.approx(0.5 / (1 + w_tau ** 2) ** (thermcal.COMP_STAGES / 2), abs=0.03)


def test_quick_ramp_and_plateaus_lie_inside_its_calibrated_range():
    q = thermcal.QUICK
    lo, hi = min(q.cal_plateaus_c), max(q.cal_plateaus_c)
    assert all(lo < t < hi for t in q.verify_plateaus_c + q.ramp[:2])
    assert not set(q.verify_plateaus_c) & set(q.cal_plateaus_c)


def test_comp_thermometer_starts_where_the_firmwares_does():
    # A gyro-sim log's first row has P_f = 0 (before the first P update); the firmware's
    # P_c starts at P_f once P_f has settled (comp_filters.h), so a slow P_c must not
    # creep up from that 0 for its time constants and read as a temperature change.
    log = _log(lambda t: np.where(t < 0.05, 0.0, 25.0), 300.0)
    t = log["t_s"]
    p_c = thermcal.comp_thermometer(t, log["p_f_deg"], 20.0)
    after = t >= thermcal.START_S
    assert np.max(np.abs(p_c[after] - 25.0)) < 1e-9


def _noise_log(dur_s, slow_dps, seed=1):
    # rate_unc: white, 0.1 deg/s per sample at 100 Hz; rate_dps: the same plus a slow
    # wander (white noise through a 20 s low-pass) that the 1 s deviation hardly sees.
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, dur_s, 0.01)
    unc = 0.1 * rng.standard_normal(t.size)
    keep = np.exp(-0.01 / 20.0)
    from scipy.signal import lfilter
    lead = 20000  # 10 time constants of the low-pass, dropped: a stationary wander
    slow = lfilter([1 - keep], [1, -keep], rng.standard_normal(t.size + lead))[lead:]
    slow *= slow_dps / np.sqrt((1 - keep) / (1 + keep))
    return {"t_s": t, "rate_unc_dps": unc, "rate_dps": unc + slow}


def test_noise_ratio_judged_at_10s_on_a_long_record():
    proto = thermcal.FULL
    # Within 1.1x at 1 s, well beyond it at 10 s: a failed verification.
    r = thermcal.verify_noise(_noise_log(proto.noise_s + thermcal.START_S, 0.01), proto)
    assert r["ratio"] <= thermcal.LIMITS["noise_ratio"]
    assert r["ratio_10s"] > 1.5
    assert r["ratio_10s_judged"] and not r["ok"]
    assert "10 s (judged)" in r["how"]
    # No slow wander: both ratios about 1, passed.
    r = thermcal.verify_noise(_noise_log(proto.noise_s + thermcal.START_S, 0.0), proto)
    assert r["ratio_10s"] == pytest.approx(1.0, abs=1e-9) and r["ok"]


def test_noise_ratio_at_10s_reported_only_on_a_short_record():
    proto = thermcal.QUICK
    r = thermcal.verify_noise(_noise_log(proto.noise_s + thermcal.START_S, 0.01), proto)
    assert r["ratio_10s"] > 1.5
    assert not r["ratio_10s_judged"] and r["ok"]
    assert "reported" in r["how"]


def test_each_protocol_fits_with_its_own_thermometer_filter():
    # The full protocol's settled plateaus take the slow three-stage thermometer; the quick
    # one's 400 s plateaus are all transients and keep one 5 s stage (with three of 15 s the
    # default part's quick calibration left -0.39 deg/s at 20 degC).
    assert (thermcal.FULL.comp_tau_s, thermcal.FULL.comp_stages) == (15.0, 3)
    assert (thermcal.QUICK.comp_tau_s, thermcal.QUICK.comp_stages) == (5.0, 1)
