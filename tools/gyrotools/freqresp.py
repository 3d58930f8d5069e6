"""Second-order resonance fit of a frequency sweep (thesis 7.2.2, fig. 7-3, 7-5).

Sweep CSV format (written by the simulator's and the firmware's self-calibration sweep,
read with csvlog; '#' lines are comments, more columns may follow):

    f_hz, amp, phase_deg
    800, 0.01233, -1.9
    802, 0.01236, -1.9
    ...

    f_hz       excitation frequency of the drive FORCE in Hz (with half-frequency drive
               the voltages run at f_hz / 2), any order, > 0
    amp        response amplitude at f_hz, linear (not dB), > 0, any consistent unit
               (demodulated pickoff volts at constant drive, or volts per volt)
    phase_deg  response phase relative to the force, degrees, wrapped or not

Model: the drive mode's displacement answer to force (a second-order low-pass) seen
through the electronics and the demodulator, which add a phase lag, constant or growing
linearly with frequency (a pure delay tau):

    H(f) = K w0^2 exp(-j (phi0 + 2 pi f tau)) / (w0^2 - w^2 + j w w0 / Q),  w = 2 pi f

so the phase at resonance is -90 deg - phi0 - 360 f0 tau (the thesis measured -99.56).

Fit:
1. Start: 1/H = e^{j phi0}/(K w0^2) (w0^2 - w^2 + j w w0/Q) is linear in three complex
   coefficients when tau = 0: complex least squares (rows weighted by |H|, so each point
   counts by its relative error) gives f0, Q, K, phi0.
2. Refine with scipy.optimize.least_squares on log-amplitude and wrapped phase
   residuals (one natural unit each: a 1 % amplitude error weighs as a 0.01 rad phase
   error), with tau free when lag="linear".

Reported: undamped resonance f0, Q, DC gain K, peak gain (linear and dB) and its
frequency f0 sqrt(1 - 1/(2Q^2)), the -3 dB points of the fitted curve and the thesis's
Q estimate f_peak / (f_hi - f_lo), the phase at f0, 1-sigma parameter uncertainties
from the Jacobian, and the RMS residuals.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import optimize

from . import csvlog
from .errors import InputError

SWEEP_COLUMNS = ("f_hz", "amp", "phase_deg")
MIN_POINTS = 8


def read_sweep(path):
    """f_hz, amp, phase_deg arrays of a sweep CSV, sorted by frequency, validated."""
    log = csvlog.read_log(path, need=SWEEP_COLUMNS, time_column=None, min_rows=MIN_POINTS,
                          purpose="the frequency-response fit")
    f, amp, ph = log["f_hz"], log["amp"], log["phase_deg"]
    if np.any(f <= 0):
        raise InputError(f"{path}: f_hz must be > 0 (row {int(np.argmax(f <= 0)) + 1})")
    if np.any(amp <= 0):
        raise InputError(f"{path}: amp must be > 0, linear not dB "
                         f"(row {int(np.argmax(amp <= 0)) + 1})")
    order = np.argsort(f, kind="stable")
    return f[order], amp[order], ph[order]


def model(f_hz, f0_hz, q, k, phi0_deg, tau_s=0.0):
    """Complex H(f) of the module doc."""
    w = 2 * np.pi * np.asarray(f_hz, dtype=float)
    w0 = 2 * np.pi * f0_hz
    lag = np.deg2rad(phi0_deg) + w * tau_s
    return k * w0 ** 2 * np.exp(-1j * lag) / (w0 ** 2 - w ** 2 + 1j * w * w0 / q)


def _linear_fit(f, h):
    """Linear complex least squares on 1/H = a0 + a1 (j w) + a2 w^2 (normalised w)."""
    w_ref = 2 * np.pi * float(np.median(f))
    wn = 2 * np.pi * f / w_ref
    wt = np.abs(h)
    a = np.column_stack([np.ones_like(wn), 1j * wn, wn ** 2]).astype(complex) * wt[:, None]
    coef, *_ = np.linalg.lstsq(a, wt / h, rcond=None)
    resid = float(np.linalg.norm(a @ coef - wt / h))
    return coef, w_ref, resid


def _initial(f, h, lag="linear"):
    """Starting point of the nonlinear fit: the linear fit on 1/H after removing a trial
    pure delay tau (0..200 us on a 1 us grid for the "linear" lag model). A delay makes
    the lag grow linearly with frequency; over a sweep that covers only the resonance the
    basis {1, j w, w^2} is nearly collinear and the delay's slope would otherwise be
    absorbed into nonsense coefficients (a board's 1.5-sample DAC latency is 30 us)."""
    taus = np.arange(0.0, 200e-6 + 1e-12, 1e-6) if lag == "linear" else np.array([0.0])
    best = None
    for tau in taus:
        hc = h * np.exp(1j * 2 * np.pi * f * tau)
        coef, w_ref, res = _linear_fit(f, hc)
        a0, a1, a2 = coef
        if abs(a2) == 0.0 or abs(a1) == 0.0 or not (-(a0 / a2).real > 0):
            continue
        if best is None or res < best[0]:
            best = (res, coef, w_ref, tau)
    if best is None:
        raise InputError("the sweep does not look like a second-order resonance "
                         "(no peak to fit)")
    _, (a0, a1, a2), w_ref, tau = best
    w0n = math.sqrt(-(a0 / a2).real)
    q = abs(a2) * w0n / abs(a1)
    k = 1.0 / (abs(a2) * w0n ** 2)
    phi0 = math.degrees(np.angle(-a2))
    return w0n * w_ref / (2 * np.pi), q, k, phi0, tau


@dataclasses.dataclass
class FreqRespResult:
    f0_hz: float
    q: float
    k_dc: float
    phi0_deg: float
    tau_s: float
    lag: str
    f0_std_hz: float
    q_std: float
    f_peak_hz: float
    peak_gain: float
    f_3db_lo_hz: float
    f_3db_hi_hz: float
    q_from_3db: float
    phase_at_f0_deg: float
    rms_amp_db: float
    rms_phase_deg: float
    measured_peak_f_hz: float
    measured_peak_amp: float
    f_hz: np.ndarray
    amp: np.ndarray
    phase_deg: np.ndarray


def _minus_3db(f0, q, k, peak):
    """Frequencies where |H| = peak / sqrt(2): roots v = (f/f0)^2 of
    v^2 - (2 - 1/Q^2) v + 1 - 2 K^2 / peak^2 = 0."""
    b = 2.0 - 1.0 / q ** 2
    c = 1.0 - 2.0 * k ** 2 / peak ** 2
    disc = b * b - 4 * c
    if disc < 0:
        return math.nan, math.nan
    roots = [(b - math.sqrt(disc)) / 2, (b + math.sqrt(disc)) / 2]
    lo, hi = (f0 * math.sqrt(v) if v > 0 else math.nan for v in roots)
    return lo, hi


def fit(f_hz, amp, phase_deg, lag="linear"):
    """Fit the model of the module doc; lag is "const" (tau = 0) or "linear"."""
    if lag not in ("const", "linear"):
        raise InputError(f"lag model '{lag}' is not const or linear")
    f = np.asarray(f_hz, dtype=float)
    amp = np.asarray(amp, dtype=float)
    ph = np.asarray(phase_deg, dtype=float)
    if f.size < MIN_POINTS or np.unique(f).size < MIN_POINTS // 2:
        raise InputError(f"{np.unique(f).size} distinct frequencies; the fit needs at least "
                         f"{MIN_POINTS // 2} (and {MIN_POINTS} points)")
    h = amp * np.exp(1j * np.deg2rad(ph))
    f0, q, k, phi0, tau0 = _initial(f, h, lag)
    span = f.max() - f.min()
    tau_scale = 1.0 / (2 * np.pi * max(f.max(), 1e-9))   # 1 rad of lag at the top freq

    def unpack(x):
        tau = x[4] * tau_scale if lag == "linear" else 0.0
        return x[0], x[1], math.exp(x[2]), x[3], tau

    def resid(x):
        f0_, q_, k_, phi_, tau_ = unpack(x)
        hm = model(f, f0_, q_, k_, phi_, tau_)
        return np.concatenate([np.log(np.abs(hm) / amp),
                               np.angle(hm / h)])

    x0 = np.array([f0, q, math.log(k), phi0, tau0 / tau_scale])
    if lag == "const":
        x0 = x0[:4]

        def resid4(x):
            return resid(np.append(x, 0.0))
        fun = resid4
    else:
        fun = resid
    lo = [1e-9, 1e-3, -np.inf, -np.inf] + ([-np.inf] if lag == "linear" else [])
    x0[0] = min(max(x0[0], f.min() - span), f.max() + span)
    x0[1] = max(x0[1], 2e-3)
    sol = optimize.least_squares(fun, x0, bounds=(lo, np.inf), method="trf",
                                 x_scale=np.maximum(np.abs(x0), 1.0))
    x = sol.x if lag == "linear" else np.append(sol.x, 0.0)
    f0, q, k, phi0, tau = unpack(x)
    if not (f.min() <= f0 <= f.max()):
        raise InputError(f"fitted resonance {f0:.6g} Hz lies outside the sweep "
                         f"{f.min():g}..{f.max():g} Hz: the sweep must bracket it")
    # 1-sigma uncertainties from the Jacobian and the residual scatter.
    m, n = sol.fun.size, sol.x.size
    s2 = float(np.sum(sol.fun ** 2) / max(m - n, 1))
    try:
        cov = np.linalg.inv(sol.jac.T @ sol.jac) * s2
        f0_std, q_std = math.sqrt(abs(cov[0, 0])), math.sqrt(abs(cov[1, 1]))
    except np.linalg.LinAlgError:
        f0_std = q_std = math.nan
    if q > 1 / math.sqrt(2):
        f_peak = f0 * math.sqrt(1 - 1 / (2 * q * q))
        peak = k * q / math.sqrt(1 - 1 / (4 * q * q))
    else:  # no resonant peak: the low-pass is maximal at DC
        f_peak, peak = 0.0, k
    f_lo, f_hi = _minus_3db(f0, q, k, peak)
    q3 = f_peak / (f_hi - f_lo) if math.isfinite(f_lo) and math.isfinite(f_hi) else math.nan
    ph0 = -90.0 - phi0 - 360.0 * f0 * tau
    ph0 = (ph0 + 180.0) % 360.0 - 180.0
    r = fun(sol.x)
    i_pk = int(np.argmax(amp))
    return FreqRespResult(
        f0_hz=f0, q=q, k_dc=k, phi0_deg=phi0, tau_s=tau, lag=lag, f0_std_hz=f0_std,
        q_std=q_std, f_peak_hz=f_peak, peak_gain=peak, f_3db_lo_hz=f_lo, f_3db_hi_hz=f_hi,
        q_from_3db=q3, phase_at_f0_deg=ph0,
        rms_amp_db=float(np.sqrt(np.mean((r[:f.size] * 20 / math.log(10)) ** 2))),
        rms_phase_deg=float(np.degrees(np.sqrt(np.mean(r[f.size:] ** 2)))),
        measured_peak_f_hz=float(f[i_pk]), measured_peak_amp=float(amp[i_pk]),
        f_hz=f, amp=amp, phase_deg=ph)


def summary(res):
    return {
        "model": "H = K w0^2 exp(-j(phi0 + 2 pi f tau)) / (w0^2 - w^2 + j w w0/Q)",
        "lag_model": res.lag,
        "n_points": int(res.f_hz.size),
        "f0_hz": res.f0_hz,
        "f0_std_hz": res.f0_std_hz,
        "q": res.q,
        "q_std": res.q_std,
        "dc_gain": res.k_dc,
        "peak_gain": res.peak_gain,
        "peak_gain_db": 20 * math.log10(res.peak_gain),
        "f_peak_hz": res.f_peak_hz,
        "f_3db_lo_hz": res.f_3db_lo_hz,
        "f_3db_hi_hz": res.f_3db_hi_hz,
        "q_from_3db": res.q_from_3db,
        "phase_at_f0_deg": res.phase_at_f0_deg,
        "lag_phi0_deg": res.phi0_deg,
        "lag_delay_s": res.tau_s,
        "rms_residual_amp_db": res.rms_amp_db,
        "rms_residual_phase_deg": res.rms_phase_deg,
        "measured_peak_f_hz": res.measured_peak_f_hz,
        "measured_peak_amp": res.measured_peak_amp,
        "measured_peak_db": 20 * math.log10(res.measured_peak_amp),
    }


def plot(res, out_dir, name="freqresp.png", title=""):
    """Bode plot of the sweep and the fit (fig. 7-3, 7-5)."""
    from . import plotting

    f = res.f_hz
    ff = np.linspace(f.min(), f.max(), 2000)
    hm = model(ff, res.f0_hz, res.q, res.k_dc, res.phi0_deg, res.tau_s)
    fig, (a1, a2) = plotting.figure(2, 1, height_in=3.3, sharex=True)
    a1.plot(f, 20 * np.log10(res.amp), ".", ms=3, label="sweep")
    a1.plot(ff, 20 * np.log10(np.abs(hm)), "-", lw=1,
            label=f"fit: f0 {res.f0_hz:.6g} Hz, Q {res.q:.4g}, "
                  f"peak {20 * math.log10(res.peak_gain):.4g} dB")
    edges = [fx for fx in (res.f_3db_lo_hz, res.f_3db_hi_hz) if math.isfinite(fx)]
    for k, fx in enumerate(edges):
        a1.axvline(fx, ls=":", color="C2", lw=0.8,
                   label="-3 dB frequencies " + ", ".join(f"{e:.6g}" for e in edges) + " Hz"
                   if k == 0 else None)
    a1.axhline(20 * math.log10(res.peak_gain) - 10 * math.log10(2), ls=":", color="C2",
               lw=0.8, label="-3 dB level")
    plotting.finish(a1, title=title or "Frequency response", ylabel="amplitude (dB)")
    meas = np.degrees(np.unwrap(np.deg2rad(res.phase_deg)))
    fit_ph = np.degrees(np.unwrap(np.angle(hm)))
    # Put the measured phase on the fit's branch (a sweep may be offset by 360 deg).
    i = int(np.argmin(np.abs(ff[:, None] - f[None, :1]).ravel()))
    meas += 360.0 * np.round((fit_ph[i] - meas[0]) / 360.0)
    a2.plot(f, meas, ".", ms=3, label="sweep")
    a2.plot(ff, fit_ph, "-", lw=1,
            label=f"fit: {res.phase_at_f0_deg:.4g} deg at f0")
    a2.axvline(res.f0_hz, ls=":", color="k", lw=0.8, label=f"f0 {res.f0_hz:.6g} Hz")
    plotting.finish(a2, xlabel="frequency (Hz)", ylabel="phase (deg)")
    return plotting.save(fig, out_dir, name)
