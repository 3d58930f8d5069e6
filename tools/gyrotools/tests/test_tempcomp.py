"""tempcomp: a synthetic cool-down (the thesis's 62.4 -> 36.2 degC, P through (7-12)) with
a known bias polynomial in P and white noise: the blocked CV must pick the true order
and the coefficients must come back. Tolerances are 5 standard deviations of the
coefficient scatter measured over 40 seeds (10 Hz log, 0.3 deg/s per-sample noise,
1 s bins): order 1 c0 0.004, c1 0.005; order 2 c0 0.008, c1 0.021, c2 0.010; order 3
c0 0.015, c1 0.059, c2 0.062, c3 0.019 deg/s per deg^i. The true order was chosen in
40 of 40 seeds for each of orders 1, 2, 3."""
import numpy as np
import pytest
from scipy import signal

from gyrotools import tempcomp
from gyrotools.errors import InputError

FS = 10.0
T_END = 1800.0
THESIS = [58.533, 34.59]                  # B = 34.59 P + 58.533 (7.3.2)


def p_of_t(t):
    """Cool-down from 62.4 to 36.2 degC, exponential, expressed as P with (7-12)."""
    temp = 36.19 + (62.42 - 36.19) * np.exp(-t / 600.0)
    return (temp - 34.703) / 12.961, temp


def cooldown(coeffs, seed, white=0.3):
    g = np.random.default_rng(seed)
    t = np.arange(int(T_END * FS)) / FS
    p, temp = p_of_t(t)
    bias = np.polynomial.polynomial.polyval(p, coeffs) + g.standard_normal(t.size) * white
    # The board sensor follows the structure through a 300 s thermal lag.
    a = np.exp(-1 / (300.0 * FS))
    board = signal.lfilter([1 - a], [1, -a], temp, zi=[a * temp[0]])[0]
    return t, p + 0.002 * g.standard_normal(t.size), bias, board


def fit(coeffs, seed, **kw):
    t, p, y, board = cooldown(coeffs, seed)
    b = tempcomp.bin_average(t, {"p": p, "y": y, "tb": board}, 1.0)
    return b, tempcomp.fit_bias(b["p"], b["y"], "p_deg", **kw)


@pytest.mark.parametrize("coeffs, tol", [
    (THESIS, [0.02, 0.025]),
    (THESIS + [-2.0], [0.04, 0.1, 0.05]),
    (THESIS + [-2.0, 1.0], [0.075, 0.3, 0.3, 0.1]),
])
def test_true_order_and_coefficients(coeffs, tol):
    _, f = fit(coeffs, seed=41)
    print(f"tempcomp order {len(coeffs) - 1}: chose {f.order}, coeffs "
          f"{np.round(f.coeffs, 4).tolist()}, residual std {f.residual_std:.4f}")
    assert f.order == len(coeffs) - 1
    assert np.all(np.abs(f.coeffs - coeffs) < tol)
    # The residual is the bin noise: 0.3 / sqrt(10 samples per bin).
    assert f.residual_std == pytest.approx(0.3 / np.sqrt(10), rel=0.1)
    assert f.cv_rmse[f.order] < f.cv_rmse[0] / 10


def test_drive_phase_beats_a_lagging_board_sensor():
    b, pf = fit(THESIS, seed=42)
    tf = tempcomp.fit_bias(b["tb"], b["y"], "t_board_c")
    print(f"tempcomp P vs board: {pf.residual_std:.3f} vs {tf.residual_std:.3f} deg/s")
    assert pf.residual_std < tf.residual_std / 5
    assert tf.residual_p2p > 1.0


def test_spikes_are_dropped_on_request():
    t, p, y, _ = cooldown(THESIS, seed=43)
    b = tempcomp.bin_average(t, {"p": p, "y": y}, 1.0)
    spikes = np.arange(50, 1800, 170)
    b["y"][spikes] += 5.0
    plain = tempcomp.fit_bias(b["p"], b["y"], "p_deg")
    clean = tempcomp.fit_bias(b["p"], b["y"], "p_deg", despike=5.0)
    assert np.count_nonzero(~clean.kept) == spikes.size
    assert not clean.kept[spikes].any()
    assert clean.residual_std < plain.residual_std / 3
    assert np.all(np.abs(clean.coeffs - THESIS) < [0.02, 0.025])


def test_scale_factor_against_p_from_a_rate_table_at_temperature():
    """Six temperatures x five rates. Over 200 seeds the SF order was right in 190 (the
    CV of 30 segments is noisier than that of 1800 bins); s0 scattered by 2e-5
    relative, r1 by 0.8 %: tolerances of 5 sigma."""
    s0, r1 = 1.0, -2.0e-3            # SF(P) = s0 (1 + r1 P)
    g = np.random.default_rng(44)
    rates, temps = [0, 50, -50, 100, -100], [0.2, 0.6, 1.0, 1.4, 1.8, 2.1]
    x, pp, y = [], [], []
    for pv in temps:
        for r in rates:
            x.append(r)
            pp.append(pv + 1e-4 * g.standard_normal())
            y.append(np.polyval(THESIS[::-1], pv) + r * s0 * (1 + r1 * pv)
                     + 0.003 * g.standard_normal())
    sf = tempcomp.fit_sf(x, y, pp, bias_order=1)
    print(f"tempcomp SF: order {sf.sf_order}, rel {np.round(sf.sf_rel_coeffs, 6).tolist()}")
    assert sf.sf_order == 1
    assert sf.sf_coeffs[0] == pytest.approx(s0, rel=1e-4)
    assert sf.sf_rel_coeffs[1] == pytest.approx(r1, rel=0.04)
    assert sf.bias_coeffs == pytest.approx(THESIS, abs=0.01)


def test_bin_average_and_blocks():
    t = np.arange(35) * 0.1
    b = tempcomp.bin_average(t, {"y": t * 2}, 1.0)
    np.testing.assert_allclose(b["t_s"], [0.45, 1.45, 2.45, 3.2])
    np.testing.assert_allclose(b["y"], [0.9, 2.9, 4.9, 6.4])
    bl = tempcomp.blocks(10, 3)
    assert [len(x) for x in bl] == [3, 4, 3] and np.concatenate(bl).tolist() == list(range(10))


def test_bad_input():
    with pytest.raises(InputError, match="needs at least 50"):
        tempcomp.fit_bias(np.arange(20.0), np.arange(20.0), "p_deg")
    with pytest.raises(InputError, match="does not change"):
        tempcomp.fit_bias(np.ones(100), np.arange(100.0), "p_deg")
    with pytest.raises(InputError, match="> 0"):
        tempcomp.bin_average(np.arange(5.0), {}, 0.0)


def test_isothermal_log_is_refused():
    """A log without a temperature change: P is only its noise, and a 'fit' of the bias
    against it is noise against noise (it once gave a slope of -14.8). Refused loudly."""
    rng = np.random.default_rng(3)
    p = 25.7 + 0.002 * rng.standard_normal(600)
    b = 0.1 * rng.standard_normal(600)
    with pytest.raises(InputError, match="temperature change"):
        tempcomp.fit_bias(p, b, "P")


def test_a_slow_ramp_is_not_taken_for_noise():
    """The refusal compares P's span with its bin-to-bin scatter, which a trend has none
    of: a small, clean ramp still fits."""
    rng = np.random.default_rng(4)
    p = np.linspace(25.0, 25.05, 600) + 0.0005 * rng.standard_normal(600)
    b = 30.0 * (p - 25.0) + 0.01 * rng.standard_normal(600)
    fit = tempcomp.fit_bias(p, b, "P")
    assert fit is not None


def test_firmware_values_are_in_deviation_from_the_span_middle():
    # A fit in absolute P near 26 deg: the firmware's polynomial in x = P - ref gives the
    # same bias, ref is the middle of the span, the range half of it, no gradient term.
    p = np.linspace(24.0, 28.0, 400)
    y = 58.533 + 34.59 * p - 0.2 * p ** 2 + 0.003 * p ** 3
    fit = tempcomp.fit_bias(p, y + 1e-6 * np.sin(p * 37.0), "p_deg", max_order=3)
    v = tempcomp.firmware_bias(fit)
    assert v["cal.ref_p_deg"] == pytest.approx(26.0, abs=1e-9)
    assert v["rate.p_range_deg"] == pytest.approx(2.0, abs=1e-9)
    assert v["rate.bias_grad_dps_per_deg"] == 0.0
    c = [v["rate.bias_c0_dps"], v["rate.bias_c1_dps_per_deg"], v["rate.bias_c2_dps_per_deg2"],
         v["rate.bias_c3_dps_per_deg3"]]
    x = p - 26.0
    got = c[0] + c[1] * x + c[2] * x ** 2 + c[3] * x ** 3
    assert np.max(np.abs(got - tempcomp.poly_eval(fit.coeffs, p))) < 1e-9
