"""Demodulation calibration on synthetic segment data with a known phase error."""
import math

import numpy as np
import pytest

from gyrotools import demodcal
from gyrotools.errors import InputError


def _segments(true_err_deg, gain, quad, rates, noise, rng):
    # Output frame: the rate response sits at the phase error, the quadrature 90 deg on.
    a = math.radians(true_err_deg)
    z = [gain * r * np.exp(1j * a) + 1j * quad * np.exp(1j * a) + 0.3 for r in rates]
    z = np.array(z) + noise * (rng.standard_normal(len(rates)) + 1j * rng.standard_normal(len(rates)))
    return z.real, z.imag


def test_recovers_phase_and_scale():
    rng = np.random.default_rng(4)
    rates = [0, 20, -20, 40, -40, 80, -80, 160, -160]
    r, q = _segments(2.5, 0.8, 1500.0, rates, 1e-3, rng)
    res = demodcal.calibrate(rates, r, q, phase_deg=60.0, scale_dps=100.0)
    # Noise 1e-3 per segment over +-160 deg/s: standard error ~3e-4 deg; allow 5 of them.
    assert abs(res.phase_deg - 62.5) < max(5 * res.alpha_se_deg, 1e-9)
    assert res.alpha_se_deg < 1e-3
    assert res.scale_dps == pytest.approx(125.0, rel=5e-5)
    # Quadrature at zero rate in the corrected frame: Im{(j 1500 e^{ja} + 0.3) e^{-ja}} / gain.
    a = math.radians(2.5)
    assert res.quad_dps == pytest.approx((1500.0 - 0.3 * math.sin(a)) / 0.8, rel=1e-4)
    # The leakage bound reflects the noise: 1e-3 deg/s over +-160 deg/s.
    assert res.leakage_bound < 1e-4


def test_corrected_frame_has_no_leakage():
    # Applying the correction to the synthetic outputs leaves quadrature out of rate.
    rng = np.random.default_rng(5)
    rates = [0, 50, -50, 100, -100]
    r, q = _segments(-7.0, 1.1, 1500.0, rates, 0.0, rng)
    res = demodcal.calibrate(rates, r, q, phase_deg=0.0, scale_dps=1.0)
    z = (np.asarray(r) + 1j * np.asarray(q)) * np.exp(-1j * math.radians(res.alpha_deg)) / res.gain
    assert np.allclose(z.real - z.real[0], np.asarray(rates) - rates[0], atol=1e-9)
    assert res.leakage_bound < 1e-12


def test_rejects_single_rate():
    with pytest.raises(InputError):
        demodcal.calibrate([10, 10], [1, 1], [0, 0], 0.0, 1.0)


@pytest.mark.parametrize("err_deg", [3.0, 100.0])
def test_table_aligned_whatever_the_phase_error(err_deg):
    """A log without truth starting before the table: the schedule's start is found from
    the step edges of the output vector, even with the response far off the rate axis."""
    fs, dwell, lead = 100.0, 4.0, 3.7
    rates = [0, 40, -40, 80, -80, 160, -160, 0]
    truth = np.concatenate([np.zeros(int(lead * fs))] + [np.full(int(dwell * fs), float(x))
                                                          for x in rates])
    a = math.radians(err_deg)
    rng = np.random.default_rng(7)
    z = (0.9 * truth + 1j * 1500.0) * np.exp(1j * a) + 0.05 * rng.standard_normal(truth.size)
    t = np.arange(truth.size) / fs
    table = [(float(x), dwell) for x in rates]
    assert demodcal.align(t, z.real, z.imag, table) == pytest.approx(lead, abs=0.02)
    res = demodcal.analyse(t, z.real, z.imag, 60.0, 100.0, table=table, settle_s=0.5)
    assert res.phase_deg == pytest.approx(60.0 + err_deg, abs=0.01)
