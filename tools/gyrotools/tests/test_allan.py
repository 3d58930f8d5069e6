"""allan: the ADEV of rate data and the N, B, R read-offs against noise of known
coefficients (IEEE two-sided definitions in synth.py), alone and mixed.

Tolerances are about 4 standard deviations of the estimator's scatter, measured over 20
seeds with these record lengths (2^18 samples at 100 Hz unless said):
white N 0.13 %; flicker B -0.9 % mean, 0.3 % std (1/f below 1/T is missing from a
finite record); ramp R 0.4 %; mixed N 0.2 %, B (curve minimum) 1.6 %, R 5.5 %;
low-passed white + flicker (2^18 at 1 kHz) N -0.6 % mean, 1.9 % std; rate random walk
(2^20 samples, 30 seeds) K -4.0 % mean, 6.3 % std, worst -19 % (the +1/2 term shares
its few long taus with the flicker and ramp terms)."""
import math

import numpy as np
import pytest
import synth
from scipy import signal

from gyrotools import allan
from gyrotools.errors import InputError

FS = 100.0
NS = 2 ** 18
# The thesis's uncompensated part (thesis table 7-3): N = 26.4/sqrt(2) deg/h/rtHz,
# B = 31.3 deg/h; the ramp is scaled so that the flat region spans about two decades.
N_T, B_T, R_T = 18.7, 31.3, 1323.0


def rng(seed):
    return np.random.default_rng(seed)


def test_oadev_is_the_allan_variance_of_rate_averages():
    """Independent reference: (7-3) with overlapping averages of the RATE samples."""
    y = rng(0).standard_normal(4096) * 0.01 + 0.3
    curve = allan.adev_curve(y, 50.0, taus="octave")
    c = np.concatenate([[0.0], np.cumsum(y)])
    for m, ad in zip(curve.m, curve.adev_dph):
        ybar = (c[m:] - c[:-m]) / m
        d = ybar[m:] - ybar[:-m]
        ref = math.sqrt(0.5 * np.mean(d * d)) * 3600.0
        assert ad == pytest.approx(ref, rel=1e-9), m
    assert curve.tau_s[0] == pytest.approx(1 / 50.0)


def test_the_two_flicker_references_agree():
    """The discrete-time integral and the closed form (7-8) meet once sampling stops
    mattering, and both approach the 0.664 B floor."""
    for m in (32, 256):
        d = synth.allan_var_discrete(m, FS, lambda f: synth.flicker_psd2(f, B_T))
        c = synth.flicker_avar_continuous(m / FS, B_T, FS / 2)
        assert math.sqrt(d) == pytest.approx(math.sqrt(c), rel=1e-3)
    assert math.sqrt(synth.flicker_avar_continuous(1e4, B_T, FS / 2)) == pytest.approx(
        0.6643 * B_T, rel=1e-3)


def test_white_noise_gives_n_and_no_floor_or_ramp():
    res = allan.analyse(synth.white_dps(NS, FS, N_T, rng(1)), FS)
    s = allan.summary(res)
    print(f"white: N {res.arw_dph_rthz:.4f} (true {N_T})")
    assert res.arw_dph_rthz == pytest.approx(N_T, rel=0.01)
    assert s["arw_deg_per_rth"] == pytest.approx(N_T / 60, rel=0.01)
    assert res.bias_instability_upper_bound
    assert res.rate_ramp_dph_per_s is None and s["rate_ramp_dph_per_h"] is None


def test_flicker_floor_is_0664_b():
    x = synth.flicker_dps(NS, FS, B_T, rng(2))
    res = allan.analyse(x, FS)
    print(f"flicker: B {res.bias_instability_dph:.3f} (true {B_T})")
    assert res.bias_instability_dph == pytest.approx(B_T, rel=0.03)
    assert not res.bias_instability_upper_bound
    assert res.arw_dph_rthz is None
    # The measured curve follows the discrete-time theory within its confidence interval.
    tau = res.curve.tau_s
    sel = tau <= NS / FS / 20
    theory = synth.allan_theory_dph(tau[sel], FS, b_dph=B_T)
    half_width = np.log(res.ci_hi_dph[sel] / res.ci_lo_dph[sel]) / 2
    z = np.abs(np.log(res.curve.adev_dph[sel] / theory)) / half_width
    assert np.all(z < 3.5) and np.mean(z < 1) > 0.5
    assert theory[-1] == pytest.approx(allan.FLICKER_FLOOR * B_T, rel=0.01)


def test_rate_ramp_from_the_plus_one_slope():
    r_dph_h = 15480.0  # the thesis's 4.30 deg/s/h
    x = synth.white_dps(NS, FS, N_T, rng(3)) + synth.ramp_dps(NS, FS, r_dph_h)
    s = allan.summary(allan.analyse(x, FS))
    print(f"white+ramp: R {s['rate_ramp_dph_per_h']:.1f} (true {r_dph_h}), "
          f"N {s['arw_dph_per_rthz']:.4f}")
    assert s["rate_ramp_dph_per_h"] == pytest.approx(r_dph_h, rel=0.02)
    assert s["rate_ramp_dps_per_h"] == pytest.approx(4.30, rel=0.02)
    assert s["arw_dph_per_rthz"] == pytest.approx(N_T, rel=0.01)
    assert s["rate_ramp_source"] == "slope +1 region"


def test_mixed_white_flicker_ramp_and_the_sigma_1s_bias():
    g = rng(4)
    x = (synth.white_dps(NS, FS, N_T, g) + synth.flicker_dps(NS, FS, B_T, g)
         + synth.ramp_dps(NS, FS, R_T))
    res = allan.analyse(x, FS)
    s = allan.summary(res)
    grid = np.logspace(-1, math.log10(NS / FS / 4), 120)
    b_expected = synth.allan_theory_dph(grid, FS, N_T, B_T, 0, R_T).min() / allan.FLICKER_FLOOR
    print(f"mixed: N {res.arw_dph_rthz:.3f} (true {N_T}), B {res.bias_instability_dph:.3f} "
          f"(curve-min theory {b_expected:.3f}, true {B_T}), R {s['rate_ramp_dph_per_h']:.0f} "
          f"(true {R_T}), sigma(1 s)/N {s['adev_at_1s_dph'] / N_T:.3f}")
    assert res.arw_dph_rthz == pytest.approx(N_T, rel=0.02)
    # Reading sigma(1 s) as N is biased high by about 50 % with the thesis's figures.
    assert 1.35 < s["adev_at_1s_dph"] / N_T < 1.65
    assert res.bias_instability_dph == pytest.approx(b_expected, rel=0.05)
    assert res.bias_instability_dph == pytest.approx(B_T, rel=0.08)
    assert s["bias_instability_floor_term_dph"] == pytest.approx(B_T, rel=0.08)
    assert s["rate_ramp_dph_per_h"] == pytest.approx(R_T, rel=0.15)
    lo, hi = res.ci_lo_dph, res.ci_hi_dph
    assert np.all(lo < res.curve.adev_dph) and np.all(res.curve.adev_dph < hi)


def test_low_passed_output_skips_the_smoothed_taus():
    fs, n = 1000.0, 2 ** 18
    g = rng(5)
    sos = signal.butter(4, 100.0, fs=fs, output="sos")   # the rate channel's output LPF
    x = signal.sosfilt(sos, synth.white_dps(n, fs, N_T, g) + synth.flicker_dps(n, fs, B_T, g))
    res = allan.analyse(x, fs)
    print(f"low-passed: fit from {res.tau_min_fit_s} s, N {res.arw_dph_rthz:.3f}")
    assert res.tau_min_fit_s >= 0.03
    assert res.arw_dph_rthz == pytest.approx(N_T, rel=0.06)
    forced = allan.analyse(x, fs, tau_min_s=1 / fs)   # smoothed taus ruin the read-off
    assert forced.arw_dph_rthz is None or abs(forced.arw_dph_rthz / N_T - 1) > 0.1


def test_rate_random_walk_term_on_request():
    k = 20.0
    n = 2 ** 20
    x = synth.white_dps(n, FS, 5.0, rng(1000)) + synth.rrw_dps(n, FS, k, rng(2000))
    res = allan.analyse(x, FS, include_rrw=True)
    print(f"rrw: K {res.rrw_dph_rts * 60:.2f} (true {k})")
    assert res.rrw_dph_rts * 60 == pytest.approx(k, rel=0.25)
    assert allan.analyse(x, FS).model["K_dph_rts"] == 0.0


def test_bad_input():
    with pytest.raises(InputError, match="at least 256"):
        allan.analyse(np.zeros(100), FS)
    with pytest.raises(InputError, match="non-finite"):
        allan.analyse(np.full(1000, np.nan), FS)
    with pytest.raises(InputError, match="does not vary"):
        allan.analyse(np.full(5000, 3.0), FS)
    with pytest.raises(InputError, match="too short for an Allan fit"):
        allan.analyse(synth.white_dps(4096, FS, 1.0, rng(8)), FS, tau_min_s=5.0)
