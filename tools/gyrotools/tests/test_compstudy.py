"""compstudy's offline compensation is the firmware's formula: on a synthetic log whose
uncompensated rate is a known cubic of the thermometer, the fitted-form output is zero
once the filters have settled, and the filter's lag shows as the polynomial's slope times
stages x tau on a ramp of P."""

import numpy as np
import pytest

from gyrotools import compstudy, thermcal

V = {"cal.ref_p_deg": 25.0, "rate.grad_tau_s": 10.0, "rate.bias_grad_dps_per_deg": 0.0,
     "rate.bias_c0_dps": -6.0, "rate.bias_c1_dps_per_deg": 35.0,
     "rate.bias_c2_dps_per_deg2": 0.1, "rate.bias_c3_dps_per_deg3": 0.01,
     "rate.sf_c1_per_deg": 0.0, "rate.sf_c2_per_deg2": 0.0, "rate.sf_c3_per_deg3": 0.0,
     "rate.sf_c4_per_deg4": 0.0}


def _bias(x):
    return V["rate.bias_c0_dps"] + x * (V["rate.bias_c1_dps_per_deg"] + x * (
        V["rate.bias_c2_dps_per_deg2"] + x * V["rate.bias_c3_dps_per_deg3"]))


def test_constant_thermometer_compensated_to_zero():
    t = np.arange(0.0, 400.0, 0.1)
    p = np.full_like(t, 25.3)
    log = {"t_s": t, "p_f_deg": p, "rate_unc_dps": np.full_like(t, _bias(0.3))}
    out = compstudy.compensate(log, V, 15.0, 3)
    assert np.max(np.abs(out[t >= thermcal.START_S])) < 1e-9


@pytest.mark.parametrize("stages", [1, 2, 3])
def test_ramp_lag_is_stages_times_tau(stages):
    t = np.arange(0.0, 2000.0, 0.1)
    slope = 1e-3  # deg/s
    p = 25.0 + slope * np.maximum(t - 100.0, 0.0)
    log = {"t_s": t, "p_f_deg": p}
    v = dict(V, **{"rate.bias_c2_dps_per_deg2": 0.0, "rate.bias_c3_dps_per_deg3": 0.0})
    log["rate_unc_dps"] = v["rate.bias_c0_dps"] + 35.0 * (p - 25.0)
    out = compstudy.compensate(log, v, 15.0, stages)
    # steady ramp: the output is the slope times the thermometer's lag, stages x tau (a
    # sampled stage's lag is keep dt / (1 - keep) = tau - dt/2 to first order)
    keep = np.exp(-0.1 / 15.0)
    lag_s = stages * keep * 0.1 / (1.0 - keep)
    assert lag_s == pytest.approx(stages * 15.0, rel=5e-3)
    assert out[-1] == pytest.approx(35.0 * slope * lag_s, rel=1e-4)
