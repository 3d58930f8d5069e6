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
    assert half_d == pytest.approx(0.5, abs=0.03)  # P_c's 5 s low-pass trims the peaks


def test_quick_ramp_and_plateaus_lie_inside_its_calibrated_range():
    q = thermcal.QUICK
    lo, hi = min(q.cal_plateaus_c), max(q.cal_plateaus_c)
    assert all(lo < t < hi for t in q.verify_plateaus_c + q.ramp[:2])
    assert not set(q.verify_plateaus_c) & set(q.cal_plateaus_c)
