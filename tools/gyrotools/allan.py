"""Allan deviation of the rate output and its noise read-offs (thesis 7.2.1, (7-1)..(7-11)).

Convention (IEEE Std 952 / 1431, the two-sided one of the thesis (7-4)..(7-10)); every
deviation is in deg/h, every tau in s:

    angle random walk   sigma(tau) = N / sqrt(tau)         (7-6), slope -1/2
    bias instability    sigma floor = sqrt(2 ln2 / pi) B = 0.664 B   (7-8), slope 0
    rate random walk    sigma(tau) = K sqrt(tau / 3)       slope +1/2
    rate ramp           sigma(tau) = R tau / sqrt(2)       (7-10), slope +1

N in deg/h/sqrt(Hz) equals N in deg/h*sqrt(s); N / 60 is deg/sqrt(h). A one-sided
spectrum (analyser, Welch) shows sqrt(2) N for the same noise (see psd.py).

Method
------
1. Overlapping ADEV by allantools.oadev with the rate as FREQUENCY data
   (data_type="freq", rate = sample rate): the rate is the derivative of the angle, so
   the angle is the "phase". Feeding rate as phase data is a common bench mistake and
   gives a different, wrong curve.
2. The variance model sigma^2 = N^2/tau + F^2 + R^2 tau^2/2 (the sum (7-11); the rate
   random walk term K^2 tau/3 only on request) is fitted by weighted least squares on
   log sigma^2 (weights edf/2: the relative variance of an Allan variance estimate is
   2/edf), coefficients kept >= 0.
3. Confidence intervals: Greenhall's equivalent degrees of freedom
   (allantools.edf_greenhall, overlapping ADEV) with the noise type at each tau taken
   from the model term that dominates there, then allantools.confidence_interval
   (chi-squared, 68.3 %).
4. Read-offs, each from its own slope region:
   N  least-squares fit of slope -1/2 over the taus where the white term is at least
      half the fitted variance, after subtracting the other fitted terms. Reading
      sigma(1 s) instead is biased high when flicker is present (with the thesis's
      figures, N = 18.7 and 0.664 B = 20.8 deg/h, by about 50 %); it is reported only
      for comparison.
   B  the flat minimum of the fitted curve / 0.664 (IEEE read-off: it includes what the
      neighbouring terms add at the minimum). The minimum of the raw points is given
      too; it is biased low by the scatter of the points, so it is not the read-off.
      When the curve still falls at the longest tau, B is only an upper bound and is
      flagged.
   R  least-squares fit of slope +1 over the taus where the ramp term is at least half
      the fitted variance, other terms subtracted.
5. Leading taus that the output low-pass smooths (there the curve rises or is flat
   before the -1/2 region) are excluded from the fit: if the curve starts with an
   octave slope above -0.35 and later reaches -0.35, the fit starts ten times later
   than that point (a low-pass of cutoff fc still lowers sigma by about 1 % at
   tau = 7/fc). `tau_min_s` overrides.
"""

from __future__ import annotations

import dataclasses
import math

import allantools
import numpy as np
from scipy import optimize

from .errors import InputError

DPH_PER_DPS = 3600.0
FLICKER_FLOOR = math.sqrt(2.0 * math.log(2.0) / math.pi)  # 0.6643, (7-8) for x -> inf
CI_LEVEL = 0.6826894921370859                              # one sigma
MIN_SAMPLES = 256
# Noise type (allantools alpha: S_y(f) ~ f^alpha) of each model term, rate as frequency.
_ALPHA = {"white": 0, "flicker": -1, "rrw": -2, "ramp": -2}
_TERMS = ("white", "flicker", "rrw", "ramp")


@dataclasses.dataclass
class AllanCurve:
    tau_s: np.ndarray
    adev_dph: np.ndarray
    m: np.ndarray           # averaging factors, tau = m / fs
    n_samples: int
    fs_hz: float


@dataclasses.dataclass
class AllanResult:
    curve: AllanCurve
    ci_lo_dph: np.ndarray
    ci_hi_dph: np.ndarray
    edf: np.ndarray
    fit_mask: np.ndarray            # taus used by the model fit
    model: dict                     # N_dph_rthz, F_dph, K_dph_rts, R_dph_per_s (SI time)
    arw_dph_rthz: float             # N (two-sided), deg/h/sqrt(Hz) = deg/h*sqrt(s)
    arw_source: str                 # "slope -1/2 region" or why it is None
    arw_tau_range_s: tuple
    bias_instability_dph: float     # fitted-curve minimum / 0.664
    bias_instability_upper_bound: bool
    tau_at_min_s: float
    adev_min_model_dph: float
    adev_min_measured_dph: float
    adev_min_measured_ci_dph: tuple
    tau_at_min_measured_s: float
    rate_ramp_dph_per_s: float      # R in deg/h per s; None if not resolved
    ramp_source: str
    ramp_tau_range_s: tuple
    rrw_dph_rts: float              # K in deg/h/sqrt(s)
    adev_at_1s_dph: float           # measured, for comparison only; None if out of range
    tau_min_fit_s: float


def adev_curve(rate_dps, fs_hz, taus="log", per_decade=10, max_frac=0.25):
    """Overlapping ADEV (deg/h) of a rate series (deg/s) sampled at fs_hz.

    taus: "log" (per_decade log-spaced averaging factors) or "octave" (1, 2, 4, ...);
    the longest tau is max_frac of the record.
    """
    rate_dps = np.asarray(rate_dps, dtype=float)
    n = rate_dps.size
    if n < MIN_SAMPLES:
        raise InputError(f"{n} samples; the Allan deviation needs at least {MIN_SAMPLES}")
    if not np.all(np.isfinite(rate_dps)):
        raise InputError("rate contains non-finite values")
    if not (fs_hz > 0 and math.isfinite(fs_hz)):
        raise InputError(f"sample rate {fs_hz} Hz is not positive")
    m_max = max(1, int(n * max_frac))
    if taus == "octave":
        m = 2 ** np.arange(0, int(math.floor(math.log2(m_max))) + 1)
    elif taus == "log":
        k = max(2, int(round(per_decade * math.log10(m_max))) + 1)
        m = np.unique(np.round(np.logspace(0.0, math.log10(m_max), k)).astype(int))
    else:
        raise InputError(f"unknown tau spacing '{taus}' (use log or octave)")
    rate_dph = rate_dps * DPH_PER_DPS
    # Rate is the time derivative of angle: it is FREQUENCY-type data for allantools.
    tau, ad, _err, _ns = allantools.oadev(rate_dph, rate=fs_hz, data_type="freq",
                                          taus=m / fs_hz)
    m_used = np.round(tau * fs_hz).astype(int)
    ok = np.isfinite(ad) & (ad > 0)
    if np.count_nonzero(ok) < 6:
        raise InputError("the rate does not vary (Allan deviation zero at most taus): "
                         "nothing to analyse")
    return AllanCurve(tau_s=tau[ok], adev_dph=ad[ok], m=m_used[ok], n_samples=n,
                      fs_hz=float(fs_hz))


def model_terms(tau_s, model):
    """Variance of each model term at tau_s, as a dict of arrays ((deg/h)^2)."""
    tau_s = np.asarray(tau_s, dtype=float)
    return {
        "white": model["N_dph_rthz"] ** 2 / tau_s,
        "flicker": np.full_like(tau_s, model["F_dph"] ** 2),
        "rrw": model["K_dph_rts"] ** 2 * tau_s / 3.0,
        "ramp": model["R_dph_per_s"] ** 2 * tau_s ** 2 / 2.0,
    }


def model_adev(tau_s, model):
    """Fitted total Allan deviation (deg/h) at tau_s: the sum (7-11)."""
    return np.sqrt(sum(model_terms(tau_s, model).values()))


def _edf(curve, alphas):
    n_phase = curve.n_samples + 1  # allantools integrates n rates into n + 1 phases
    return np.array([allantools.edf_greenhall(alpha=int(a), d=2, m=int(m), N=n_phase,
                                              overlapping=True, modified=False)
                     for a, m in zip(alphas, curve.m)])


def _fit(tau, var, edf, include_rrw):
    """Non-negative (N^2, F^2, K^2, R^2) minimising sum edf/2 (ln var - ln model)^2."""
    cols = [1.0 / tau, np.ones_like(tau), tau / 3.0, tau ** 2 / 2.0]
    scale = np.array([np.max(var * tau), np.max(var), np.max(3 * var / tau),
                      np.max(2 * var / tau ** 2)])
    active = [0, 1, 2, 3] if include_rrw else [0, 1, 3]
    basis = np.column_stack([cols[i] for i in active])
    scale = scale[active]
    w = np.sqrt(edf / 2.0)
    # Linear start: relative residuals in the variance domain, solved by NNLS.
    p0, _ = optimize.nnls(basis * (w / var)[:, None], w)
    p0 = np.maximum(p0, 1e-9 * scale)

    def resid(p):
        return w * (np.log(basis @ p) - np.log(var))

    sol = optimize.least_squares(resid, p0, bounds=(0.0, np.inf), x_scale=scale,
                                 method="trf")
    p = sol.x
    # A term the data does not support is set to exactly zero.
    for i in range(len(active)):
        trial = p.copy()
        trial[i] = 0.0
        if np.sum(resid(trial) ** 2) <= np.sum(resid(p) ** 2) * (1 + 1e-9):
            p = trial
    full = np.zeros(4)
    full[active] = p
    return full


def _auto_tau_min(curve):
    """Start of the fit: past the low-pass-smoothed leading taus (see module doc)."""
    tau, ad = curve.tau_s, curve.adev_dph
    lt, la = np.log(tau), np.log(ad)
    record_s = curve.n_samples / curve.fs_hz
    usable = (tau * 2.0 <= tau[-1]) & (tau <= record_s / 100.0)  # high-edf taus only
    if not usable.any():
        return float(tau[0])
    slope = (np.interp(lt + math.log(2.0), lt, la) - la) / math.log(2.0)
    idx = np.flatnonzero(usable)
    if slope[idx[0]] <= -0.35:
        return float(tau[0])
    white = idx[slope[idx] <= -0.35]
    if white.size == 0:
        return float(tau[0])
    return float(min(tau[white[0]] * 10.0, tau[-1] / 8.0))


def _region_fit(tau, var, edf, terms, name, power):
    """Fixed-slope fit of term `name` (variance ~ tau^power) where it is >= half."""
    total = sum(terms.values())
    own = terms[name]
    region = own >= 0.5 * total
    if np.count_nonzero(region) < 3:
        return None, (None, None)
    rest = total - own
    resid_var = var[region] - rest[region]
    good = resid_var > 0
    if np.count_nonzero(good) < 3:
        return None, (None, None)
    t, v, w = tau[region][good], resid_var[good], edf[region][good] / 2.0
    # ln v = ln c + power ln t with the slope fixed: ln c is the weighted mean.
    ln_c = np.sum(w * (np.log(v) - power * np.log(t))) / np.sum(w)
    return math.exp(ln_c), (float(t[0]), float(t[-1]))


def analyse(rate_dps, fs_hz, taus="log", per_decade=10, max_frac=0.25, tau_min_s=None,
            include_rrw=False):
    """Allan deviation, confidence intervals, fitted model and the N, B, R read-offs.

    The model has the three terms of the thesis (7-11) - white, flicker, ramp - and a
    rate-random-walk term only with include_rrw: on a record of ordinary length the
    +1/2 and +1 slopes share the few long taus and trade off against each other.
    """
    curve = adev_curve(rate_dps, fs_hz, taus=taus, per_decade=per_decade,
                       max_frac=max_frac)
    tau, ad = curve.tau_s, curve.adev_dph
    var = ad ** 2
    tmin = _auto_tau_min(curve) if tau_min_s is None else float(tau_min_s)
    mask = tau >= tmin * (1 - 1e-9)
    if np.count_nonzero(mask) < 6:
        raise InputError(
            f"only {np.count_nonzero(mask)} taus at or above tau_min = {tmin:.4g} s; the "
            "log is too short for an Allan fit (need 6)")
    # Two passes: white-noise edf for the first fit, then the edf of the noise type the
    # first fit says dominates each tau.
    edf = _edf(curve, np.zeros(tau.size))
    model = None
    for _ in range(2):
        p = _fit(tau[mask], var[mask], edf[mask], include_rrw)
        model = {"N_dph_rthz": math.sqrt(p[0]), "F_dph": math.sqrt(p[1]),
                 "K_dph_rts": math.sqrt(p[2]), "R_dph_per_s": math.sqrt(p[3])}
        terms = model_terms(tau, model)
        dominant = np.argmax(np.vstack([terms[t] for t in _TERMS]), axis=0)
        edf = _edf(curve, [_ALPHA[_TERMS[i]] for i in dominant])
    ci = [allantools.confidence_interval(a, e, ci=CI_LEVEL) for a, e in zip(ad, edf)]
    lo, hi = (np.array([c[k] for c in ci], dtype=float) for k in (0, 1))

    terms_fit = {k: v[mask] for k, v in model_terms(tau, model).items()}
    n_reg, n_range = _region_fit(tau[mask], var[mask], edf[mask], terms_fit, "white", -1.0)
    if n_reg is not None:
        arw, arw_src = math.sqrt(n_reg), "slope -1/2 region"
    else:
        arw, arw_src = None, "not resolved: white noise never dominates the fitted taus"
    r_reg, r_range = _region_fit(tau[mask], var[mask], edf[mask], terms_fit, "ramp", 2.0)
    if r_reg is not None:
        ramp, ramp_src = math.sqrt(2.0 * r_reg), "slope +1 region"
    else:
        ramp, ramp_src = None, "not resolved: the ramp never dominates the fitted taus"

    # Flat minimum of the fitted curve over the fitted tau range (dense log grid).
    grid = np.logspace(math.log10(tau[mask][0]), math.log10(tau[mask][-1]), 400)
    fitted = model_adev(grid, model)
    i_min = int(np.argmin(fitted))
    # Still falling at the longest tau (log slope below -0.1): only an upper bound.
    end_slope = math.log(fitted[-1] / fitted[-2]) / math.log(grid[-1] / grid[-2])
    upper = end_slope < -0.1
    j = int(np.argmin(np.where(mask, ad, np.inf)))
    at1 = None
    if tau[0] <= 1.0 <= tau[-1]:
        at1 = float(math.exp(np.interp(0.0, np.log(tau), np.log(ad))))
    return AllanResult(
        curve=curve, ci_lo_dph=lo, ci_hi_dph=hi, edf=edf, fit_mask=mask, model=model,
        arw_dph_rthz=arw, arw_source=arw_src, arw_tau_range_s=n_range,
        bias_instability_dph=float(fitted[i_min] / FLICKER_FLOOR),
        bias_instability_upper_bound=bool(upper), tau_at_min_s=float(grid[i_min]),
        adev_min_model_dph=float(fitted[i_min]), adev_min_measured_dph=float(ad[j]),
        adev_min_measured_ci_dph=(float(lo[j]), float(hi[j])),
        tau_at_min_measured_s=float(tau[j]),
        rate_ramp_dph_per_s=ramp, ramp_source=ramp_src, ramp_tau_range_s=r_range,
        rrw_dph_rts=model["K_dph_rts"], adev_at_1s_dph=at1, tau_min_fit_s=tmin)


def summary(res):
    """Flat dict of the figures (units in the names), for JSON and printing."""
    arw = res.arw_dph_rthz
    ramp = res.rate_ramp_dph_per_s
    m = res.model
    return {
        "convention": "IEEE two-sided: sigma=N/sqrt(tau), floor=0.664*B, "
                      "sigma=K*sqrt(tau/3), sigma=R*tau/sqrt(2)",
        "n_samples": res.curve.n_samples,
        "fs_hz": res.curve.fs_hz,
        "duration_s": res.curve.n_samples / res.curve.fs_hz,
        "input_data_type": "freq (rate), allantools.oadev",
        "arw_dph_per_rthz": arw,
        "arw_deg_per_rth": None if arw is None else arw / 60.0,
        "arw_one_sided_asd_dph_per_rthz": None if arw is None else arw * math.sqrt(2.0),
        "arw_source": res.arw_source,
        "arw_fit_tau_range_s": list(res.arw_tau_range_s),
        "adev_at_1s_dph": res.adev_at_1s_dph,
        "bias_instability_dph": res.bias_instability_dph,
        "bias_instability_is_upper_bound": res.bias_instability_upper_bound,
        "bias_instability_floor_term_dph": m["F_dph"] / FLICKER_FLOOR,
        "adev_min_fit_dph": res.adev_min_model_dph,
        "tau_at_min_s": res.tau_at_min_s,
        "adev_min_measured_dph": res.adev_min_measured_dph,
        "adev_min_measured_ci68_dph": list(res.adev_min_measured_ci_dph),
        "tau_at_min_measured_s": res.tau_at_min_measured_s,
        "rate_ramp_dph_per_h": None if ramp is None else ramp * 3600.0,
        "rate_ramp_dps_per_h": None if ramp is None else ramp,
        "rate_ramp_source": res.ramp_source,
        "rate_ramp_fit_tau_range_s": list(res.ramp_tau_range_s),
        "rate_random_walk_dph_per_rth": m["K_dph_rts"] * 60.0,
        "fit_tau_min_s": res.tau_min_fit_s,
        "model_N_dph_per_rthz": m["N_dph_rthz"],
        "model_B_dph": m["F_dph"] / FLICKER_FLOOR,
        "model_K_dph_per_rth": m["K_dph_rts"] * 60.0,
        "model_R_dph_per_h": m["R_dph_per_s"] * 3600.0,
        "tau_s": res.curve.tau_s.tolist(),
        "adev_dph": res.curve.adev_dph.tolist(),
        "adev_ci68_lo_dph": res.ci_lo_dph.tolist(),
        "adev_ci68_hi_dph": res.ci_hi_dph.tolist(),
        "edf": res.edf.tolist(),
    }


def fit_agreement(res, z=1.96):
    """Boolean per tau: the fitted sum lies inside the point's interval widened from
    68 % to about 95 % (log width scaled by z; a 68 % test would fail a third of the
    points of a perfect fit by chance). A fit that misses the data must not be drawn or
    read as if it described it."""
    ad = res.curve.adev_dph
    lo = ad * (res.ci_lo_dph / ad) ** z
    hi = ad * (res.ci_hi_dph / ad) ** z
    model = model_adev(res.curve.tau_s, res.model)
    return (model >= lo) & (model <= hi)


def b_supported(res):
    """(True, '') when B can be read off the fitted sum: it follows the data at its
    minimum and over at least 2/3 of the fitted taus; else (False, why)."""
    ok = fit_agreement(res)
    j = int(np.argmin(np.abs(np.log(res.curve.tau_s / res.tau_at_min_s))))
    n_in, n_fit = int(np.count_nonzero(ok & res.fit_mask)), int(np.count_nonzero(res.fit_mask))
    if ok[j] and 3 * n_in >= 2 * n_fit:
        return True, ""
    return False, (f"the fitted sum misses the data (follows it at {n_in} of {n_fit} taus"
                   + ("" if ok[j] else ", not at its minimum") + ")")


def _span(grid, rng, pad=2.0):
    """Grid points within a fit's tau range (widened by pad either side)."""
    lo, hi = rng
    if lo is None:
        return np.zeros(grid.shape, dtype=bool)
    return (grid >= lo / pad) & (grid <= hi * pad)


def plot(res, out_dir, name="allan.png", title=""):
    """Log-log ADEV with 68 % CIs, the fitted sum and its asymptotes (fig. 7-1, 7-11),
    each drawn only where it describes the data: the fitted sum where it lies inside
    the points' 68 % intervals, each asymptote over the taus its read-off came from."""
    from . import plotting

    fig, ax = plotting.figure()
    draw(ax, res)
    ax.set_ylim(res.curve.adev_dph.min() / 3, res.curve.adev_dph.max() * 3)
    plotting.finish(ax, title=title or "Allan deviation of the rate output",
                    xlabel="averaging time tau [s]", ylabel="Allan deviation [deg/h]")
    return plotting.save(fig, out_dir, name)


def draw_points(ax, res, color="C0", what=""):
    """The measured curve and its 68 % confidence band; `what` names the series in the
    legend (a figure with two curves)."""
    tau = res.curve.tau_s
    ax.fill_between(tau, res.ci_lo_dph, res.ci_hi_dph, color=color, alpha=0.25,
                    label=f"68 % confidence interval{what and ' (' + what + ')'}")
    ax.loglog(tau, res.curve.adev_dph, "o", ms=3, color=color,
              label=f"overlapping ADEV{what and ' of ' + what}")


def draw(ax, res, what=""):
    """plot()'s curve, fit and read-offs on the axes ax (another figure can hold them)."""
    tau = res.curve.tau_s
    draw_points(ax, res, "C0", what)
    grid = np.logspace(math.log10(tau[0]), math.log10(tau[-1]), 300)
    ok = fit_agreement(res)
    ok_grid = np.interp(np.log(grid), np.log(tau), ok.astype(float)) > 0.5
    ok_grid &= grid >= res.tau_min_fit_s * (1 - 1e-9)
    fitted = np.where(ok_grid, model_adev(grid, res.model), np.nan)
    n_fit = int(np.count_nonzero(res.fit_mask))
    n_in = int(np.count_nonzero(ok & res.fit_mask))
    ax.loglog(grid, fitted, "-", color="k", lw=1,
              label=f"fitted sum (7-11), drawn where it fits: {n_in} of {n_fit} taus")
    if res.arw_dph_rthz is not None:
        g = grid[_span(grid, res.arw_tau_range_s)]
        ax.loglog(g, res.arw_dph_rthz / np.sqrt(g), "--", color="C1",
                  label=f"N = {res.arw_dph_rthz:.3g} deg/h/rtHz  (slope -1/2)")
    _plot_floor(ax, res, grid)
    if res.rate_ramp_dph_per_s is not None:
        r = res.rate_ramp_dph_per_s
        g = grid[_span(grid, res.ramp_tau_range_s)]
        ax.loglog(g, r * g / math.sqrt(2.0), "--", color="C3",
                  label=f"R = {r * 3600:.3g} deg/h/h  (slope +1)")
    if res.model["K_dph_rts"] > 0:
        k = res.model["K_dph_rts"]
        g = grid[grid >= res.tau_min_fit_s]
        ax.loglog(g, k * np.sqrt(g / 3.0), ":", color="C4",
                  label=f"K = {k * 60:.3g} deg/h/rth  (slope +1/2)")
    if res.tau_min_fit_s > tau[0]:
        ax.axvspan(tau[0], res.tau_min_fit_s, color="0.85", alpha=0.5, lw=0,
                   label="not fitted (smoothed by the output low-pass)")


def _plot_floor(ax, res, grid):
    """The bias-instability floor 0.664 B around the fitted minimum, only where the
    fitted sum describes the data; otherwise a legend line says why not."""
    b = res.bias_instability_dph
    near = (grid >= res.tau_at_min_s / 4) & (grid <= res.tau_at_min_s * 4)
    if b_supported(res)[0]:
        ax.loglog(grid[near], np.full(np.count_nonzero(near), FLICKER_FLOOR * b), "--",
                  color="C2", label=("B < " if res.bias_instability_upper_bound else "B = ")
                  + f"{b:.3g} deg/h  (0.664 B)")
        ax.plot([res.tau_at_min_s], [res.adev_min_model_dph], "v", color="C2",
                label="minimum of the fitted sum")
    else:
        ax.plot([], [], " ", label="B not read: the fitted sum misses the data "
                                   "(the measured curve is the guide)")


def _quantization(res):
    """IEEE 952 quantization noise Q (deg): sigma = sqrt(3) Q / tau where the curve
    falls with slope -1 (local log slope below -0.8 over an octave); None when no tau
    shows that slope (a filtered rate output usually hides it)."""
    tau, ad = res.curve.tau_s, res.curve.adev_dph
    if tau.size < 3:
        return None
    slope = np.gradient(np.log(ad), np.log(tau))
    steep = slope < -0.8
    if np.count_nonzero(steep) < 2:
        return None
    q_deg = ad[steep] / DPH_PER_DPS * tau[steep] / math.sqrt(3.0)
    return float(np.median(q_deg))


def ieee952(res):
    """The five coefficients of IEEE Std 952-1997 annex C, each with its unit and how it
    was obtained (None with the reason when the record does not show it)."""
    q = _quantization(res)
    arw = res.arw_dph_rthz
    k = res.model["K_dph_rts"]
    ramp = res.rate_ramp_dph_per_s
    b_ok, b_why = b_supported(res)

    def entry(value, unit, source):
        return {"value": value, "unit": unit, "source": source}

    return {
        "Q": entry(q, "deg", "slope -1 region, sigma = sqrt(3) Q / tau" if q is not None
                   else "not observable: no slope -1 region (the output low-pass hides it)"),
        "N": entry(None if arw is None else arw / 60.0, "deg/sqrt(h)", res.arw_source),
        "B": entry(res.bias_instability_dph if b_ok else None, "deg/h",
                   ("upper bound: the curve still falls at the longest tau"
                    if res.bias_instability_upper_bound else "flat minimum of the fitted sum / 0.664")
                   if b_ok else f"not observable: {b_why}"),
        "K": entry(k * 60.0 if k > 0 else None, "deg/h/sqrt(h)",
                   "fitted +1/2 term (--rrw)" if k > 0 else
                   "not observable: no +1/2 slope in the record (fit with --rrw to try)"),
        "R": entry(None if ramp is None else ramp * 3600.0, "deg/h/h", res.ramp_source),
    }


def kalibr_yaml(res, ieee, fs_hz, source):
    """Text of a Kalibr IMU file (imu.yaml): the gyroscope's white-noise density and
    random walk in SI units, the accelerometer entries marked as not measured."""
    d2r = math.pi / 180.0
    n = res.arw_dph_rthz if res.arw_dph_rthz is not None else res.model["N_dph_rthz"]
    n_note = "from N" if res.arw_dph_rthz is not None else "from the fitted white term (N not resolved)"
    noise = n / DPH_PER_DPS * d2r  # deg/h/rtHz -> rad/s/rtHz
    if ieee["K"]["value"] is not None:
        k_dps = res.model["K_dph_rts"] / DPH_PER_DPS  # deg/s per sqrt(s)
        walk, k_note = k_dps * d2r, "from K (IEEE 952 rate random walk)"
    else:
        # K is not in the record: the deviation at the longest tau bounds it from above
        # (K sqrt(tau/3) cannot exceed what was measured there), which is what a filter
        # needs - a conservative value, said to be one.
        t_max, a_max = res.curve.tau_s[-1], res.curve.adev_dph[-1]
        walk = a_max / DPH_PER_DPS * math.sqrt(3.0 / t_max) * d2r
        k_note = (f"UPPER BOUND: K not observable in this {res.curve.n_samples / fs_hz:.0f} s "
                  f"record; sigma({t_max:.4g} s) * sqrt(3 / {t_max:.4g} s) bounds it")
    return (
        f"# IMU noise model for Kalibr / VIO (continuous-time densities), from {source}\n"
        "# by gyro-allan (IEEE Std 952 two-sided Allan deviation, allantools.oadev).\n"
        "# This device is a single-axis gyroscope: the accelerometer entries are not\n"
        "# measured; replace the .nan values with your accelerometer's figures.\n"
        "accelerometer_noise_density: .nan   # [ m / s^2 / sqrt(Hz) ]  not measured\n"
        "accelerometer_random_walk: .nan     # [ m / s^3 / sqrt(Hz) ]  not measured\n"
        f"gyroscope_noise_density: {noise:.6e}   # [ rad / s / sqrt(Hz) ]  {n_note}\n"
        f"gyroscope_random_walk: {walk:.6e}     # [ rad / s^2 / sqrt(Hz) ]  {k_note}\n"
        "rostopic: /imu0\n"
        f"update_rate: {fs_hz:.6g}   # [ Hz ]  sample rate of the log\n")
