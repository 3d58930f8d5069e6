"""Noise density of the rate output from its spectrum (thesis 7.2.4 item 2, fig. 7-10).

The thesis read the white level off a (one-sided) spectrum analyser within 100 Hz:
53.1 uV/rtHz / 7.25 mV/(deg/s) = 26.4 deg/h/rtHz. The same figure here:

- Welch's averaged periodogram (scipy.signal.welch, Hann window, 50 % overlap, linear
  detrend per segment) gives the ONE-SIDED PSD G(f), (deg/s)^2/Hz, whose integral over
  0..fs/2 is the variance. Its square root is the amplitude spectral density (ASD).
- White level: the MEDIAN of G over a band (default 1..100 Hz, clipped below Nyquist),
  robust against spurs, the 1/f rise at the low edge and the output low-pass roll-off
  at the high edge. A Welch bin is distributed as G chi2(nu)/nu with nu about twice the
  number of segments, so the median is divided by median(chi2(nu))/nu (a < 2 % PSD
  correction for >= 16 segments) to estimate the mean level.
- Equivalent Allan/IEEE coefficient (two-sided, sigma = N/sqrt(tau)):
  N = one-sided ASD / sqrt(2). 1 deg/s/rtHz = 3600 deg/h/rtHz; deg/rth = N / 60.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import signal, stats

from .errors import InputError

DPH_PER_DPS = 3600.0
MIN_SAMPLES = 256
MIN_BINS = 5


@dataclasses.dataclass
class PsdResult:
    f_hz: np.ndarray
    psd_one_sided: np.ndarray       # (unit)^2/Hz
    n_segments: int
    nperseg: int
    fs_hz: float
    band_hz: tuple                  # band actually used
    n_bins: int
    white_psd_one_sided: float      # (unit)^2/Hz, median-based, bias-corrected
    white_asd_one_sided: float      # unit/rtHz


def default_nperseg(n, fs_hz, f_lo_hz):
    """Power-of-two segment: resolution <= f_lo/4, and at least ~16 segments."""
    want = 4.0 * fs_hz / max(f_lo_hz, 1e-9)
    npow = 2 ** int(math.ceil(math.log2(max(want, 16))))
    cap = 2 ** int(math.floor(math.log2(max(n // 8, 16))))
    return int(min(npow, cap))


def analyse(x, fs_hz, band_hz=(1.0, 100.0), nperseg=None):
    """Welch one-sided PSD of x and its white level over band_hz (see module doc)."""
    x = np.asarray(x, dtype=float)
    n = x.size
    if n < MIN_SAMPLES:
        raise InputError(f"{n} samples; the noise density needs at least {MIN_SAMPLES}")
    if not np.all(np.isfinite(x)):
        raise InputError("signal contains non-finite values")
    if np.ptp(x) == 0:
        raise InputError("the signal is constant: it has no noise to measure")
    f_lo, f_hi = float(band_hz[0]), float(band_hz[1])
    if not (0 <= f_lo < f_hi):
        raise InputError(f"band {f_lo}..{f_hi} Hz is empty")
    nyq = fs_hz / 2.0
    if f_lo >= nyq:
        raise InputError(f"band starts at {f_lo} Hz, at or above Nyquist ({nyq:g} Hz)")
    if nperseg is None:
        nperseg = default_nperseg(n, fs_hz, f_lo if f_lo > 0 else f_hi / 50.0)
    nperseg = int(nperseg)
    if not 16 <= nperseg <= n:
        raise InputError(f"segment length {nperseg} must be 16..{n} samples")
    f, pxx = signal.welch(x, fs=fs_hz, window="hann", nperseg=nperseg,
                          noverlap=nperseg // 2, detrend="linear", scaling="density",
                          return_onesided=True)
    n_seg = 1 + (n - nperseg) // (nperseg - nperseg // 2)
    # Exclude DC and the Nyquist bin (both carry half the degrees of freedom).
    hi = min(f_hi, nyq)
    sel = (f >= f_lo) & (f <= hi) & (f > 0) & (f < nyq)
    nb = int(np.count_nonzero(sel))
    if nb < MIN_BINS:
        raise InputError(
            f"only {nb} spectral bins in {f_lo:g}..{hi:g} Hz (resolution "
            f"{fs_hz / nperseg:.3g} Hz); use a longer log or a wider band")
    nu = 2.0 * n_seg
    median_over_mean = stats.chi2.median(nu) / nu
    white = float(np.median(pxx[sel]) / median_over_mean)
    if not white > 0:
        raise InputError("the signal has no noise in the band (constant or quantised "
                         "flat): no white level")
    return PsdResult(f_hz=f, psd_one_sided=pxx, n_segments=int(n_seg), nperseg=nperseg,
                     fs_hz=float(fs_hz), band_hz=(float(f[sel][0]), float(f[sel][-1])),
                     n_bins=nb, white_psd_one_sided=white,
                     white_asd_one_sided=math.sqrt(white))


def summary(res, is_rate_dps=True, unit="deg/s"):
    """Flat dict of the figures (units in the names), for JSON and printing."""
    d = {
        "convention": "one-sided Welch PSD (integral over 0..fs/2 = variance); "
                      "two-sided/Allan N = one-sided ASD / sqrt(2)",
        "fs_hz": res.fs_hz,
        "nperseg": res.nperseg,
        "n_segments": res.n_segments,
        "resolution_hz": res.fs_hz / res.nperseg,
        "band_hz": list(res.band_hz),
        "n_bins_in_band": res.n_bins,
        "white_level_estimator": "median over the band / (median(chi2(nu))/nu), "
                                 "nu = 2 x segments",
    }
    if is_rate_dps:
        asd = res.white_asd_one_sided
        d.update({
            "white_asd_one_sided_dps_per_rthz": asd,
            "white_asd_one_sided_dph_per_rthz": asd * DPH_PER_DPS,
            "arw_N_two_sided_dps_per_rthz": asd / math.sqrt(2.0),
            "arw_N_two_sided_dph_per_rthz": asd * DPH_PER_DPS / math.sqrt(2.0),
            "arw_N_deg_per_rth": asd * DPH_PER_DPS / math.sqrt(2.0) / 60.0,
        })
    else:
        d.update({"unit": unit,
                  "white_asd_one_sided_per_rthz": res.white_asd_one_sided,
                  "white_psd_one_sided_per_hz": res.white_psd_one_sided})
    return d


def plot(res, out_dir, name="psd.png", title="", is_rate_dps=True, unit="deg/s"):
    """One-sided ASD with the band and white level marked (fig. 7-10)."""
    from . import plotting

    k = DPH_PER_DPS if is_rate_dps else 1.0
    u = "deg/h" if is_rate_dps else unit
    inner = (res.f_hz > 0) & (res.f_hz < res.fs_hz / 2)   # DC and Nyquist bins are halved
    f, asd = res.f_hz[inner], np.sqrt(res.psd_one_sided[inner]) * k
    fig, ax = plotting.figure()
    ax.loglog(f, asd, lw=0.8, color="C0", label="one-sided ASD (Welch)")
    ax.axvspan(res.band_hz[0], res.band_hz[1], color="C2", alpha=0.08,
               label=f"band {res.band_hz[0]:.3g}..{res.band_hz[1]:.3g} Hz")
    w = res.white_asd_one_sided * k
    ax.axhline(w, ls="--", color="C1", label=f"white level {w:.3g} {u}/rtHz (one-sided)")
    if is_rate_dps:
        ax.axhline(w / math.sqrt(2.0), ls=":", color="C3",
                   label=f"N = {w / math.sqrt(2.0):.3g} {u}/rtHz (two-sided, Allan)")
    plotting.finish(ax, title=title or "Noise spectral density",
                    xlabel="frequency (Hz)", ylabel=f"ASD ({u}/rtHz)")
    return plotting.save(fig, out_dir, name)
