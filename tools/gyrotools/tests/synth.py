"""Synthetic gyro noise and logs of known coefficients, and their analytic statistics.

The analytic references here are independent of the code under test: spectral
definitions (IEEE Std 952 two-sided PSDs) and the Allan variance of a discrete series
computed by numerical integration of its PSD through the Allan transfer function.

Units: rates in deg/h inside the generators' definitions, returned in deg/s.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import integrate, special

DPH = 3600.0


def white_dps(n, fs_hz, n_dph_rthz, rng):
    """White rate noise with two-sided PSD N^2: sigma(tau) = N / sqrt(tau)."""
    return rng.standard_normal(n) * n_dph_rthz * math.sqrt(fs_hz) / DPH


def flicker_psd2(f_hz, b_dph):
    """Two-sided flicker PSD of (7-7), (deg/h)^2/Hz: B^2 / (2 pi f)."""
    return b_dph ** 2 / (2.0 * math.pi * f_hz)


def flicker_dps(n, fs_hz, b_dph, rng):
    """1/f rate noise with two-sided PSD B^2/(2 pi f) from 1/T up to Nyquist.

    Spectral shaping of white noise: unit-variance white noise has two-sided PSD
    1/fs, so each rfft bin is scaled by sqrt(S(f) * fs); the DC bin is zeroed.
    """
    w = rng.standard_normal(n)
    spec = np.fft.rfft(w)
    f = np.fft.rfftfreq(n, 1.0 / fs_hz)
    gain = np.zeros_like(f)
    gain[1:] = np.sqrt(flicker_psd2(f[1:], b_dph) * fs_hz)
    return np.fft.irfft(spec * gain, n) / DPH


def rrw_dps(n, fs_hz, k_dph_rth, rng):
    """Rate random walk: sigma(tau) = K sqrt(tau/3); K in deg/h/sqrt(h)."""
    k_dph_rts = k_dph_rth / 60.0
    return np.cumsum(rng.standard_normal(n)) * k_dph_rts / math.sqrt(fs_hz) / DPH


def ramp_dps(n, fs_hz, r_dph_per_h):
    """Deterministic rate ramp R t (7-9); sigma(tau) = R tau / sqrt(2) exactly."""
    t_h = np.arange(n) / fs_hz / 3600.0
    return r_dph_per_h * t_h / DPH


def allan_var_discrete(m, fs_hz, psd2):
    """Allan variance at tau = m/fs of a sampled series with two-sided PSD psd2(f).

    sigma^2 = 2 int_0^{fs/2} S(f) |H(f)|^2 df with |H|^2 = 2 sin^4(pi f m/fs) /
    (m^2 sin^2(pi f/fs)), the transfer function of (mean_{k+m} - mean_k)/sqrt(2).
    """
    def integrand(u):  # u = pi f / fs
        f = u * fs_hz / math.pi
        return psd2(f) * 2.0 * math.sin(m * u) ** 4 / (m * m * math.sin(u) ** 2)

    pts = np.linspace(0.0, math.pi / 2, min(4 * m, 2000) + 1)
    total = 0.0
    for a, b in zip(pts[:-1], pts[1:]):
        val, _ = integrate.quad(integrand, max(a, 1e-12), b, limit=200)
        total += val
    return 2.0 * total * fs_hz / math.pi


def flicker_avar_continuous(tau_s, b_dph, f0_hz):
    """(7-8), IEEE Std 952 form: Allan variance of 1/f noise cut off at f0, x = pi f0 tau:
    (2 B^2 / pi) [ln2 - sin^3 x (sin x + 4 x cos x) / (2 x^2) + Ci(2x) - Ci(4x)].
    (The thesis prints the prefactor as 2 B^2 / tau; 2 B^2 / pi is what gives the
    0.664 B floor it uses.)"""
    x = math.pi * f0_hz * tau_s
    ci2, ci4 = special.sici(2 * x)[1], special.sici(4 * x)[1]
    return (2 * b_dph ** 2 / math.pi) * (
        math.log(2) - math.sin(x) ** 3 * (math.sin(x) + 4 * x * math.cos(x)) / (2 * x * x)
        + ci2 - ci4)


def allan_theory_dph(tau_s, fs_hz, n_dph_rthz=0.0, b_dph=0.0, k_dph_rth=0.0,
                     r_dph_per_h=0.0):
    """Theoretical ADEV (deg/h) of the sum of the four processes (7-11)."""
    out = []
    for tau in np.atleast_1d(tau_s):
        m = max(1, int(round(tau * fs_hz)))
        v = n_dph_rthz ** 2 / tau
        if b_dph and m < 32:
            v += allan_var_discrete(m, fs_hz, lambda f: flicker_psd2(f, b_dph))
        elif b_dph:  # sampling no longer matters: the continuous formula (7-8)
            v += flicker_avar_continuous(tau, b_dph, fs_hz / 2.0)
        v += (k_dph_rth / 60.0) ** 2 * tau / 3.0
        v += (r_dph_per_h / 3600.0) ** 2 * tau ** 2 / 2.0
        out.append(math.sqrt(v))
    return np.array(out)


def write_log(path, columns, n_rows=None, drop=()):
    """Write a gyro log CSV with the standard header; absent columns are filled.

    columns: dict name -> array. Columns of the standard set that are not given are
    written as zeros (flags as hex), except those named in `drop`, which are left out
    entirely (a gyroctl log without truth columns).
    """
    std = ["t_s", "rate_true_dps", "rate_dps", "quad_dps", "drive_amp",
           "drive_phase_deg", "p_deg", "t_ambient_c", "t_struct_c", "t_board_c", "u1_v",
           "u2_v", "adc_drive_v", "adc_sense_v", "flags"]
    n = n_rows if n_rows is not None else len(next(iter(columns.values())))
    names = [c for c in std if c not in drop] + [c for c in columns if c not in std]
    cols = []
    for c in names:
        if c == "flags":
            cols.append(np.array(["0x%04x" % 0] * n))
        elif c in columns:
            cols.append(np.char.mod("%.10g", np.asarray(columns[c], dtype=float)))
        else:
            cols.append(np.char.mod("%.10g", np.zeros(n)))
    body = np.column_stack(cols)
    with open(path, "w") as fh:
        fh.write(", ".join(names) + "\n")
        np.savetxt(fh, body, fmt="%s", delimiter=",")
    return path
