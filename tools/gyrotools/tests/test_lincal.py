"""lincal: the linearisation fit, its rescaling into the firmware's values, the sub-range
slopes and the bias between rests."""

import numpy as np
import pytest

from gyrotools import lincal


def _table(c2, c3, s=1.02, b=0.3, noise=0.0, seed=0):
    """Means u of a part whose L(u) = s r + b exactly (u solved by Newton), plus noise."""
    r = np.array(lincal.FIT_RATES_DPS, dtype=float)
    u = s * r + b
    for _ in range(50):
        f = lincal.linearise(u, c2, c3) - (s * r + b)
        u -= f / (1.0 + 2.0 * c2 * u + 3.0 * c3 * u * u)
    return r, u + noise * np.random.default_rng(seed).standard_normal(r.size)


def test_fit_recovers_a_cubic():
    r, u = _table(2e-6, -3e-8)
    s, b, c2, c3 = lincal.fit(r, u)
    assert s == pytest.approx(1.02, rel=1e-9)
    assert b == pytest.approx(0.3, abs=1e-9)
    assert c2 == pytest.approx(2e-6, rel=1e-6)
    assert c3 == pytest.approx(-3e-8, rel=1e-6)


def test_rescaled_output_has_unit_slope():
    r, u = _table(2e-6, -3e-8, s=0.97)
    s, b, c2, c3 = lincal.fit(r, u)
    v = lincal.rescaled({"rate.scale_dps": 100.0, "rate.lin_c2_per_dps": 0.0,
                         "rate.lin_c3_per_dps2": 0.0}, s, c2, c3)
    # the firmware: u' = u / s (its new scale), out = L'(u')
    out = lincal.linearise(u / s, v["rate.lin_c2_per_dps"], v["rate.lin_c3_per_dps2"])
    assert v["rate.scale_dps"] == pytest.approx(100.0 / 0.97, rel=1e-9)
    assert np.polyfit(r, out, 1)[0] == pytest.approx(1.0, abs=1e-9)
    assert np.max(np.abs(out - (r + b / s))) < 1e-8


def test_rescaled_refuses_an_output_already_linearised():
    with pytest.raises(ValueError, match="already linearised"):
        lincal.rescaled({"rate.scale_dps": 1.0, "rate.lin_c2_per_dps": 1e-6}, 1.0, 0.0, 0.0)


def test_fit_needs_enough_rates():
    with pytest.raises(ValueError, match="at least 6"):
        lincal.fit([10, 20, 30], [10, 20, 30])


def test_plausible():
    assert lincal.plausible(1e-6, -1e-8, 300.0)
    assert not lincal.plausible(0.0, 1e-6, 300.0)  # 9 % at full scale


def test_subrange_slopes_of_a_cubic():
    r = np.array([30, -30, 70, -70, 150, -150, 270, -270], dtype=float)
    y = r * (1.0 + 1e-8 * r * r)  # 0.07 % more slope near full scale
    rows, sf = lincal.subrange_slopes(r, y, np.zeros_like(r))
    assert all(abs(x["to_dps"] - x["from_dps"]) >= lincal.SUBRANGE_MIN_DPS for x in rows)
    worst = rows[0]
    assert {worst["from_dps"], worst["to_dps"]} in ({150.0, 270.0}, {-270.0, -150.0})
    # slope over 150..270: 1 + 1e-8 (270^2 + 270 150 + 150^2) = 1 + 1.359e-3, against the
    # thesis range's least-squares slope
    assert worst["slope_ppm"] == pytest.approx((1 + 1.359e-3) / sf * 1e6 - 1e6, rel=1e-6)


def test_bias_between_rests():
    rates = [0, 10, 0, -10, 0]
    means = [1.0, 11.5, 2.0, -7.0, 4.0]
    b = lincal.bias_between_rests(rates, means)
    assert list(b) == [1.0, 1.5, 2.0, 3.0, 4.0]


def test_table_steps():
    st = lincal.table_steps([5, -5], 2.0, 1.0)
    assert st == [[2.0, 0], [1.0, 0], [2.0, 5], [1.0, 0], [2.0, -5], [1.0, 0]]
