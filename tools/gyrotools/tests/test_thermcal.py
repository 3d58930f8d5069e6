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


def _thermal_log(ambient_of_t, dur_s, rate_of_t=None, tau_s=400.0, seed=None):
    # A part whose structure follows its surroundings with one time constant; P reads
    # the structure at 0.03 deg/K, the bias is 35 (deg/s)/deg of P (the default part's
    # slopes), the scale factor 1. 10 Hz rows, as the flow's chamber logs.
    t = np.arange(0.0, dur_s, 0.1)
    amb = ambient_of_t(t)
    keep = np.exp(-0.1 / tau_s)
    from scipy.signal import lfilter
    ts = amb[0] + lfilter([1 - keep], [1, -keep], amb - amb[0])
    p = 25.0 + 0.03 * (ts - 25.0)
    if seed is not None:  # the thermometer's noise: white, 2e-4 deg per row
        p = p + 2e-4 * np.random.default_rng(seed).standard_normal(t.size)
    r = np.zeros_like(t) if rate_of_t is None else rate_of_t(t)
    bias = 35.0 * 0.03 * (ts - 25.0)
    return {"t_s": t, "p_f_deg": p, "t_struct_c": ts, "rate_true_dps": r,
            "rate_unc_dps": r + bias, "rate_valid": np.ones_like(t)}


def _chamber_log(proto, seed=None):
    amb, rate, dur = thermcal._plateau_profiles(proto.cal_plateaus_c, proto.dwell_s)

    def steps(spec):
        edges = np.cumsum([d for d, _ in spec])
        vals = np.array([v for _, v in spec])
        return lambda t: vals[np.minimum(np.searchsorted(edges, t, side="right"), vals.size - 1)]
    return _thermal_log(steps(amb), dur, steps(rate), seed=seed)


def test_fast_path_follows_a_transient_the_slow_one_lags():
    # Fitted on the full protocol's chamber run, applied to a heat-gun transient (the
    # surroundings to 65 degC for 600 s, then back): the slow thermometer (three 15 s
    # stages) lags the transient's reversals, the blend follows them with the fast path,
    # and at constant temperature the output is the slow path's alone.
    from gyrotools import compstudy
    proto = thermcal.FULL
    log = _chamber_log(proto, seed=3)
    v, s0, figs = thermcal.fit(log, proto.cal_plateaus_c, proto.dwell_s,
                               comp_tau_s=proto.comp_tau_s, comp_stages=proto.comp_stages,
                               comp_fast_tau_s=proto.comp_fast_tau_s)
    assert s0 == pytest.approx(1.0, abs=1e-3)
    assert v["rate.comp_fast_tau_s"] == proto.comp_fast_tau_s
    # The gradient terms take back each path's lag on a ramp: c1 x lag / tau_g.
    c1, tau_g = v["rate.bias_c1_dps_per_deg"], v["rate.grad_tau_s"]
    assert v["rate.bias_grad_dps_per_deg"] == pytest.approx(c1 * 45.0 / tau_g, rel=0.1)
    assert v["rate.grad_fast_dps_per_deg"] == pytest.approx(c1 * 5.0 / tau_g, rel=0.1)
    assert thermcal.BLEND_MIN_DPS <= v["rate.comp_blend_dps"] <= thermcal.BLEND_MAX_DPS

    base, hot, lead, heat, tau_h, tau_c, total = proto.transient

    def heat_cool(t):
        on = (t >= lead) & (t < lead + heat)
        rise = hot + (base - hot) * np.exp(-np.clip(t - lead, 0, None) / tau_h)
        top = hot + (base - hot) * np.exp(-heat / tau_h)
        fall = base + (top - base) * np.exp(-np.clip(t - lead - heat, 0, None) / tau_c)
        return np.where(t < lead, base, np.where(on, rise, fall))
    tr = _thermal_log(heat_cool, total)
    slow_only = dict(v, **{"rate.comp_fast_tau_s": 0.0})
    m = tr["t_s"] >= lead
    err_slow = compstudy.compensate(tr, slow_only, proto.comp_tau_s, proto.comp_stages)[m]
    err_blend = compstudy.compensate(tr, v, proto.comp_tau_s, proto.comp_stages)[m]
    assert np.std(err_blend) < 0.5 * np.std(err_slow)
    assert np.max(np.abs(err_blend)) < 0.5 * np.max(np.abs(err_slow))
    rest = _thermal_log(lambda t: np.full_like(t, 25.0), 600.0, seed=5)
    np.testing.assert_array_equal(
        compstudy.compensate(rest, v, proto.comp_tau_s, proto.comp_stages),
        compstudy.compensate(rest, slow_only, proto.comp_tau_s, proto.comp_stages))


# A part of known noise at 10 Hz: the uncompensated output white plus a slow first-order
# (Gauss-Markov) wander, the compensation adding an independent wander of its own; each
# term's Allan variance at 10 s is exact (from its autocovariance), so the part's true
# 10 s ratio is set by the added wander's size.
_FS, _M, _WANDER_S = 10.0, 100, 20.0


def _ar1(rng, n, sd):
    a = np.exp(-1.0 / (_FS * _WANDER_S))
    lead = int(10 * _WANDER_S * _FS)  # dropped: a stationary wander
    from scipy.signal import lfilter
    return sd * lfilter([np.sqrt(1 - a * a)], [1, -a], rng.standard_normal(n + lead))[lead:]


def _avar_ar1_10s(sd):
    a = np.exp(-1.0 / (_FS * _WANDER_S))
    h = np.arange(-(_M - 1), _M)
    w = _M - np.abs(h)
    return sd ** 2 * (np.sum(w * a ** np.abs(h)) - np.sum(w * a ** np.abs(_M + h))) / _M ** 2


def _part_log(dur_s, true_ratio_10s, seed):
    rng = np.random.default_rng(seed)
    n = int(round(dur_s * _FS))
    unc = 0.1 * rng.standard_normal(n) + _ar1(rng, n, 0.01)
    avar_unc = 0.1 ** 2 / _M + _avar_ar1_10s(0.01)
    sd_add = np.sqrt((true_ratio_10s ** 2 - 1) * avar_unc / _avar_ar1_10s(1.0))
    return {"t_s": np.arange(n) / _FS, "rate_unc_dps": unc,
            "rate_dps": unc + _ar1(rng, n, sd_add)}


SEEDS = range(1, 25)


def test_noise_ratio_at_10s_judged_on_a_record_that_tells_a_good_part_from_a_bad_one():
    # On the 1200 s record a part whose true 10 s ratio is 1.07 (within the limit; the
    # flow's parts measure 1.05..1.06 on average) failed on some noise seeds, as the
    # quad -800 part did with seed 1004: the figure's scatter, not the part.
    proto = thermcal.FULL
    lim = thermcal.LIMITS["noise_ratio"]
    dur = proto.noise_s + thermcal.START_S
    good = [thermcal.verify_noise(_part_log(dur, 1.07, s), proto) for s in SEEDS]
    assert all(r["ratio_10s_judged"] and r["ok"] for r in good), \
        [round(r["ratio_10s"], 3) for r in good]
    # The limit is not loosened: a part at 1.13 fails on every seed.
    bad = [thermcal.verify_noise(_part_log(dur, 1.13, s), proto) for s in SEEDS]
    assert not any(r["ok"] for r in bad), [round(r["ratio_10s"], 3) for r in bad]
    assert all(r["ratio_10s"] > lim for r in bad)


def test_noise_ratio_at_10s_reports_an_uncertainty_that_matches_its_scatter():
    proto = thermcal.FULL
    dur = proto.noise_s + thermcal.START_S
    rs = [thermcal.verify_noise(_part_log(dur, 1.07, s), proto) for s in SEEDS]
    sd = np.std([r["ratio_10s"] for r in rs], ddof=1)
    u = np.array([r["ratio_10s_u"] for r in rs])
    assert 0.5 < np.mean(u) / sd < 2.0
    lo, hi = np.array([r["ratio_10s_ci"] for r in rs]).T
    assert np.all(lo < np.array([r["ratio_10s"] for r in rs])) and np.all(hi > lo)
    # its interval (68 %) holds the true ratio on about as many seeds as it should
    assert 0.5 <= np.mean((lo <= 1.07) & (1.07 <= hi)) <= 0.95
