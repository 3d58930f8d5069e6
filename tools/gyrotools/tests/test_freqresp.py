"""freqresp: synthetic sweeps of the thesis's drive mode (7.2.2: f0 1489.9 Hz, Q 33.33,
peak 68.40 dB, phase -99.56 deg at resonance), with and without noise. Peak gain and
-3 dB points are checked against the true curve evaluated independently (dense grid,
root finding), not against the fit's own closed forms."""
import math

import numpy as np
import pytest
from scipy import optimize

from gyrotools import freqresp
from gyrotools.errors import InputError

F0, Q = 1489.9, 33.33
K = 10 ** (68.40 / 20) / Q          # DC gain giving about 68.4 dB at the peak
F = np.arange(800.0, 2853.0, 2.0)   # the thesis's sweep: 800..2852 Hz in 2 Hz steps


def truth(f, lag_deg=9.56, tau=0.0):
    w, w0 = 2 * np.pi * f, 2 * np.pi * F0
    return K * w0 ** 2 * np.exp(-1j * (np.deg2rad(lag_deg) + w * tau)) / (
        w0 ** 2 - w ** 2 + 1j * w * w0 / Q)


def true_figures():
    ff = np.arange(F0 - 5, F0 + 5, 1e-4)
    mag = np.abs(truth(ff))
    peak, f_peak = mag.max(), ff[np.argmax(mag)]

    def g(f):
        return abs(truth(np.array([f]))[0]) - peak / math.sqrt(2)
    lo = optimize.brentq(g, F0 - 200, f_peak)
    hi = optimize.brentq(g, f_peak, F0 + 200)
    return peak, f_peak, lo, hi


def test_noise_free_constant_lag_is_exact():
    h = truth(F)
    res = freqresp.fit(F, np.abs(h), np.degrees(np.angle(h)), lag="const")
    peak, f_peak, lo, hi = true_figures()
    assert res.f0_hz == pytest.approx(F0, rel=1e-7)
    assert res.q == pytest.approx(Q, rel=1e-6)
    assert res.k_dc == pytest.approx(K, rel=1e-6)
    assert res.phase_at_f0_deg == pytest.approx(-99.56, abs=1e-4)
    assert res.peak_gain == pytest.approx(peak, rel=1e-6)
    assert 20 * math.log10(res.peak_gain) == pytest.approx(68.40, abs=0.01)
    assert res.f_peak_hz == pytest.approx(f_peak, abs=2e-4)
    assert res.f_3db_lo_hz == pytest.approx(lo, abs=1e-3)
    assert res.f_3db_hi_hz == pytest.approx(hi, abs=1e-3)
    assert res.q_from_3db == pytest.approx(f_peak / (hi - lo), rel=1e-5)


def test_noise_free_linear_lag():
    h = truth(F, lag_deg=2.0, tau=15e-6)
    res = freqresp.fit(F, np.abs(h), np.degrees(np.angle(h)), lag="linear")
    assert res.f0_hz == pytest.approx(F0, rel=1e-7)
    assert res.q == pytest.approx(Q, rel=1e-6)
    assert res.tau_s == pytest.approx(15e-6, rel=1e-5)
    assert res.phi0_deg == pytest.approx(2.0, abs=1e-4)
    assert res.phase_at_f0_deg == pytest.approx(-90 - 2.0 - 360 * F0 * 15e-6, abs=1e-4)


@pytest.mark.parametrize("lag", ["const", "linear"])
def test_noisy_sweep(lag):
    g = np.random.default_rng(31)
    h = truth(F, lag_deg=9.56 if lag == "const" else 2.0, tau=0.0 if lag == "const" else 15e-6)
    h = h * (1 + 0.01 * g.standard_normal(F.size)) * np.exp(
        1j * np.deg2rad(0.5) * g.standard_normal(F.size))
    res = freqresp.fit(F, np.abs(h), np.degrees(np.angle(h)), lag=lag)
    peak, f_peak, lo, hi = true_figures()
    print(f"freqresp {lag}: f0 {res.f0_hz:.3f} +- {res.f0_std_hz:.3f}, Q {res.q:.3f} +- "
          f"{res.q_std:.3f}, peak {20 * math.log10(res.peak_gain):.3f} dB, "
          f"phase {res.phase_at_f0_deg:.3f}")
    # 1 % amplitude and 0.5 deg phase noise per point: the fit's own 1-sigma figures are
    # about 0.04 Hz and 0.06 in Q; the tolerances are 4 of those.
    assert abs(res.f0_hz - F0) < 4 * res.f0_std_hz and res.f0_std_hz < 0.1
    assert abs(res.q - Q) < 4 * res.q_std and res.q_std < 0.1
    assert 20 * math.log10(res.peak_gain / peak) == pytest.approx(0, abs=0.03)
    assert res.f_3db_lo_hz == pytest.approx(lo, abs=0.3)
    assert res.f_3db_hi_hz == pytest.approx(hi, abs=0.3)
    expected_phase = -99.56 if lag == "const" else -90 - 2.0 - 360 * F0 * 15e-6
    assert res.phase_at_f0_deg == pytest.approx(expected_phase, abs=0.15)
    assert res.rms_phase_deg == pytest.approx(0.5, rel=0.15)


def test_unwrapped_offset_and_unsorted_sweep_csv(tmp_path):
    h = truth(F)
    ph = np.degrees(np.unwrap(np.angle(h))) - 360.0      # another branch of the phase
    order = np.random.default_rng(1).permutation(F.size)
    path = tmp_path / "sweep.csv"
    with open(path, "w") as fh:
        fh.write("# firmware sweep\nf_hz, amp, phase_deg, extra\n")
        for i in order:
            fh.write(f"{F[i]:.3f},{abs(h[i]):.9g},{ph[i]:.9g},0\n")
    f, amp, p = freqresp.read_sweep(str(path))
    assert np.all(np.diff(f) > 0)
    res = freqresp.fit(f, amp, p, lag="const")
    assert res.f0_hz == pytest.approx(F0, rel=1e-6)
    assert res.phase_at_f0_deg == pytest.approx(-99.56, abs=1e-3)


def test_bad_sweeps(tmp_path):
    h = truth(F)
    low = F < 1300
    with pytest.raises(InputError, match="bracket"):
        freqresp.fit(F[low], np.abs(h[low]), np.degrees(np.angle(h[low])))
    with pytest.raises(InputError, match="distinct frequencies"):
        freqresp.fit(F[:5], np.abs(h[:5]), np.zeros(5))
    p = tmp_path / "s.csv"
    p.write_text("f_hz,amp,phase_deg\n" + "".join(f"{1000 + i},{-1.0 if i == 3 else 1},0\n"
                                                    for i in range(10)))
    with pytest.raises(InputError, match="amp must be > 0"):
        freqresp.read_sweep(str(p))
    p.write_text("f_hz,amplitude,phase_deg\n1,1,1\n")
    with pytest.raises(InputError, match="missing column 'amp'"):
        freqresp.read_sweep(str(p))
