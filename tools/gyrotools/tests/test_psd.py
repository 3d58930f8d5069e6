"""psd: the Welch white level of synthetic white noise of known density, one- and
two-sided. White rate noise with two-sided PSD N^2 has a one-sided ASD of sqrt(2) N
(synth.white_dps draws samples of variance N^2 fs, the definition of that PSD)."""
import math

import numpy as np
import pytest
import synth

from gyrotools import psd
from gyrotools.errors import InputError

FS = 1000.0


def test_white_density_one_and_two_sided():
    n_true = 18.7   # deg/h/rtHz, two-sided (Allan) coefficient
    x = synth.white_dps(2 ** 18, FS, n_true, np.random.default_rng(11))
    res = psd.analyse(x, FS, band_hz=(1.0, 100.0))
    s = psd.summary(res)
    print(f"psd: one-sided {s['white_asd_one_sided_dph_per_rthz']:.3f} "
          f"(true {math.sqrt(2) * n_true:.3f}), N {s['arw_N_two_sided_dph_per_rthz']:.3f}")
    # 2 x 127 segments x ~400 bins: the median estimate scatters by about 0.3 %.
    assert s["white_asd_one_sided_dph_per_rthz"] == pytest.approx(math.sqrt(2) * n_true,
                                                                   rel=0.015)
    assert s["white_asd_one_sided_dps_per_rthz"] == pytest.approx(
        math.sqrt(2) * n_true / 3600, rel=0.015)
    assert s["arw_N_two_sided_dph_per_rthz"] == pytest.approx(n_true, rel=0.015)
    assert s["arw_N_deg_per_rth"] == pytest.approx(n_true / 60, rel=0.015)
    assert res.band_hz[0] >= 1.0 and res.band_hz[1] <= 100.0
    # Parseval: the one-sided density integrates to the variance.
    df = res.f_hz[1] - res.f_hz[0]
    assert np.sum(res.psd_one_sided) * df == pytest.approx(np.var(x), rel=0.02)


def test_median_ignores_a_spur_and_the_thesis_figure():
    # 26.4 deg/h/rtHz one-sided as in 7.2.4 (the analyser), with a strong 50 Hz spur.
    one_sided = 26.4
    n = 2 ** 17
    t = np.arange(n) / FS
    x = synth.white_dps(n, FS, one_sided / math.sqrt(2), np.random.default_rng(12))
    x += 0.05 * np.sin(2 * np.pi * 50.0 * t)
    s = psd.summary(psd.analyse(x, FS))
    assert s["white_asd_one_sided_dph_per_rthz"] == pytest.approx(one_sided, rel=0.02)
    assert s["arw_N_two_sided_dph_per_rthz"] == pytest.approx(18.67, rel=0.02)


def test_band_is_clipped_below_nyquist_and_other_units():
    x = np.random.default_rng(13).standard_normal(4096) * 2.0
    res = psd.analyse(x, 100.0, band_hz=(1.0, 100.0))
    assert res.band_hz[1] < 50.0
    s = psd.summary(res, is_rate_dps=False, unit="V")
    # variance 4 spread over 0..50 Hz one-sided: 0.08 V^2/Hz
    assert s["white_psd_one_sided_per_hz"] == pytest.approx(0.08, rel=0.05)
    assert "arw_N_two_sided_dph_per_rthz" not in s


def test_bad_input():
    with pytest.raises(InputError, match="at least 256"):
        psd.analyse(np.zeros(10), FS)
    noise = np.random.default_rng(0).standard_normal(1000)
    with pytest.raises(InputError, match="at or above Nyquist"):
        psd.analyse(noise, 100.0, band_hz=(60.0, 80.0))
    with pytest.raises(InputError, match="spectral bins"):
        psd.analyse(np.random.default_rng(0).standard_normal(512), FS, band_hz=(1.0, 3.0))
    with pytest.raises(InputError, match="constant"):
        psd.analyse(np.full(4096, 2.0), FS)
    with pytest.raises(InputError, match="empty"):
        psd.analyse(noise, FS, band_hz=(5.0, 1.0))
