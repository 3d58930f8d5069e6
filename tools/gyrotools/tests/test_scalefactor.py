"""scalefactor: a synthetic rate-table log (table 7-2 rates, CW and CCW, with the output
settling through a first-order lag) of known slope, bias and cubic nonlinearity. The
expected figures are analytic: over a symmetric set of rates x, the least-squares line
of b + s x + c3 x^3 has intercept b and slope s + c3 sum(x^4)/sum(x^2)."""
import math

import numpy as np
import pytest
from scipy import signal

from gyrotools import scalefactor
from gyrotools.errors import InputError

FS = 50.0
DWELL = 6.0
RATES = [0.0] + [s * r for r in range(20, 161, 20) for s in (1, -1)] + [0.0]
B, S, C3 = 0.75, 1.0125, 4.0e-7       # deg/s, -, deg/s per (deg/s)^3
LAG_S = 0.1                            # output low-pass time constant


def table_log(bias=B, slope=S, c3=C3, slope_neg=None, noise=0.02, seed=21):
    n = int(DWELL * FS)
    r = np.repeat(RATES, n).astype(float)
    t = np.arange(r.size) / FS
    sn = slope if slope_neg is None else slope_neg
    y = bias + np.where(r >= 0, slope, sn) * r + c3 * r ** 3
    # The output follows the table through a first-order lag, as the rate channel's
    # low-pass does: the first samples of each segment have not settled.
    a = math.exp(-1 / (LAG_S * FS))
    y = signal.lfilter([1 - a], [1, -a], y, zi=[a * y[0]])[0]
    y += np.random.default_rng(seed).standard_normal(y.size) * noise
    return t, r, y


def expected(c3=C3, slope=S):
    x = np.array(RATES)
    k = np.sum(x ** 4) / np.sum(x ** 2)
    sf = slope + c3 * k
    res_in = c3 * (x ** 3 - k * x) / sf
    return sf, math.sqrt(np.mean(res_in ** 2)) / 160.0


def test_slope_bias_and_cubic_nonlinearity_from_truth_segments():
    t, r, y = table_log()
    res = scalefactor.analyse(t, y, rate_true_dps=r, settle_s=1.5)
    sf, nl = expected()
    print(f"scalefactor: SF {res.sf:.6f} (expected {sf:.6f}), bias {res.bias:.4f} ({B}), "
          f"nonlinearity {100 * res.nonlinearity:.4f} % (expected {100 * nl:.4f} %)")
    assert len(res.segments) == len(RATES)
    assert res.sf == pytest.approx(sf, rel=1e-4)
    assert res.bias == pytest.approx(B, abs=0.005)
    assert res.full_scale_dps == 160.0
    assert res.nonlinearity == pytest.approx(nl, rel=0.02)
    assert abs(res.asymmetry) < 1e-4            # an odd nonlinearity is symmetric
    # CW/CCW half differences cancel the bias, as in table 7-2.
    for rate, half in res.half_differences:
        assert half == pytest.approx(S * rate + C3 * rate ** 3, abs=0.005)


def test_settling_is_excluded():
    t, r, y = table_log(c3=0.0)
    settled = scalefactor.analyse(t, y, rate_true_dps=r, settle_s=1.5)
    unsettled = scalefactor.analyse(t, y, rate_true_dps=r, settle_s=0.0)
    assert settled.nonlinearity < 2e-5
    assert unsettled.rms_residual_dps > 10 * settled.rms_residual_dps


def test_table_schedule_for_a_log_without_truth_gives_the_same_answer():
    t, r, y = table_log()
    table = scalefactor.parse_table(",".join(f"{x:g}:{DWELL:g}" for x in RATES))
    a = scalefactor.analyse(t, y, table=table, settle_s=1.5)
    b = scalefactor.analyse(t, y, rate_true_dps=r, settle_s=1.5)
    assert a.sf == pytest.approx(b.sf, rel=1e-12)
    assert a.nonlinearity == pytest.approx(b.nonlinearity, rel=1e-9)


def test_cw_ccw_asymmetry():
    t, r, y = table_log(c3=0.0, slope=1.0, slope_neg=0.99)
    res = scalefactor.analyse(t, y, rate_true_dps=r, settle_s=1.5)
    assert res.sf_pos == pytest.approx(1.0, rel=1e-4)
    assert res.sf_neg == pytest.approx(0.99, rel=1e-4)
    assert res.asymmetry == pytest.approx(0.01 / 0.995, rel=0.01)


def test_thesis_table_7_2():
    """The thesis's own numbers: (CW - CCW)/2 output volts against rate -> 7.25 mV/(deg/s).
    Its "RMS residual" 0.5572 deg/s (0.348 % of 160 deg/s) is the residual standard
    deviation with n - 1; the RMS (1/n) reported here is 0.518 deg/s, 0.324 %."""
    rate = np.arange(20, 161, 20, dtype=float)
    volts = np.array([0.1441, 0.2892, 0.4336, 0.5845, 0.7346, 0.8684, 1.0152, 1.1584])
    res = scalefactor.fit(rate, volts)
    assert res.sf * 1000 == pytest.approx(7.25, abs=0.01)
    n = rate.size
    assert res.rms_residual_dps * math.sqrt(n / (n - 1)) == pytest.approx(0.5572, rel=0.01)
    assert 100 * res.nonlinearity == pytest.approx(0.324, abs=0.001)


@pytest.mark.parametrize("text, msg", [
    ("20:5,abc", "not RATE:DWELL"), ("20:x", "two numbers"), ("20:0", "dwell must be > 0"),
    ("", "empty rate table"),
])
def test_bad_tables(text, msg):
    with pytest.raises(InputError, match=msg):
        scalefactor.parse_table(text)


def test_too_few_segments_and_no_segmentation():
    t = np.arange(500) / FS
    with pytest.raises(InputError, match="found 1 constant-rate segments"):
        scalefactor.analyse(t, np.zeros(500), rate_true_dps=np.zeros(500))
    with pytest.raises(InputError, match="--table"):
        scalefactor.analyse(t, np.zeros(500))
    with pytest.raises(InputError, match="does not overlap"):
        scalefactor.analyse(t, np.zeros(500), table=[(10.0, 5.0)] * 3, t0_s=1000.0)


def test_negative_scale_factor_is_refused():
    """A log misaligned with its table schedule can fit a negative slope (it once
    reported -0.47 with exit 0): implausible for the product's output, refused."""
    rates = [20, -20, 40, -40, 60, -60, 80, -80]
    out = [-0.47 * r + 0.1 for r in rates]
    with pytest.raises(InputError, match="negative"):
        scalefactor.fit(rates, out)


def test_table_aligned_on_its_step_edges():
    """A gyroctl log starts before the table: the schedule is found from the step edges,
    and the scale factor is the one the truth gives."""
    t, r, y = table_log()
    lead = int(7.3 * FS)
    y2 = np.concatenate([B + 0.02 * np.random.default_rng(3).standard_normal(lead), y])
    t2 = np.arange(y2.size) / FS + 100.0
    table = scalefactor.parse_table(",".join(f"{x:g}:{DWELL:g}" for x in RATES))
    t0, corr = scalefactor.align_table(t2, y2, table)
    # The output lags the table by the channel's low-pass (LAG_S): within one lag.
    assert 107.3 <= t0 <= 107.3 + LAG_S
    assert corr > 0.98  # the cubic and the lag are not in the schedule
    a = scalefactor.analyse(t2, y2, table=table, settle_s=1.5)
    b = scalefactor.analyse(t, y, rate_true_dps=r, settle_s=1.5)
    assert a.sf == pytest.approx(b.sf, rel=1e-4)


def test_alignment_refuses_a_short_record_and_a_wrong_schedule():
    t, r, y = table_log()
    table = scalefactor.parse_table(",".join(f"{x:g}:{DWELL:g}" for x in RATES))
    with pytest.raises(InputError, match="record too short"):
        scalefactor.align_table(t[: t.size // 2], y[: t.size // 2], table)
    noise = np.random.default_rng(5).standard_normal(y.size)
    with pytest.raises(InputError, match="cannot align"):
        scalefactor.align_table(t, noise, scalefactor.parse_table("0:6,100:6,-100:6"))


def test_invalid_samples_are_left_out():
    """An analog output at its fault level while the rate is not valid (the first 0.3 s
    here, inside the first window) is no reading: with valid given it is left out of the
    means; without, the fault level pulls the first segment's mean."""
    t = np.arange(0.0, 8.0, 0.01)
    truth = np.where(t < 2, 0.0, np.where(t < 4, 50.0, np.where(t < 6, -50.0, 100.0)))
    out = 0.00725 * truth
    valid = t >= 0.3
    out = np.where(valid, out, -10.0)
    good = scalefactor.analyse(t, out, rate_true_dps=truth, settle_s=0.2, min_avg_s=0.5,
                               valid=valid)
    assert good.sf == pytest.approx(0.00725, rel=1e-9)
    assert good.rms_residual_dps < 1e-9
    bad = scalefactor.analyse(t, out, rate_true_dps=truth, settle_s=0.2, min_avg_s=0.5)
    assert bad.rms_residual_dps > 10.0
    none = np.zeros_like(valid)
    none[t >= 2] = True
    assert len(scalefactor.analyse(t, out, rate_true_dps=truth, settle_s=0.2, min_avg_s=0.5,
                                   valid=none).segments) == 3
