"""Temperature compensation fit: bias against the drive phase P (thesis 7.3, (7-12)).

The thesis's "sensorless" compensation: the drive-loop phase output P (degrees) tracks
the structure's temperature through the resonance shift (2-35), better than a board
sensor, so the bias is fitted against P:

    B(P) = c0 + c1 P + c2 P^2 + c3 P^3     (deg/s, P in deg)

(the thesis's cool-down fit was linear: B = 34.59 P + 58.533, residual 0.462 deg/s).
The gyro rests during the log, so its rate output IS the bias. Log with the firmware's
compensation off (bias coefficients 0), otherwise the fit is of the remaining bias.

Method
- Average into contiguous time bins (default 1 s): rate noise falls, row count drops,
  and P and the bias are compared over the same interval.
- Polynomial order 0..3 by k-fold cross-validation over CONTIGUOUS blocks of bins (not
  random points: neighbouring samples share slow noise and temperature, so random
  folds would reward over-fitting). Each order's CV error is the RMS prediction error
  of held-out blocks; the chosen order is the lowest whose CV mean-square error is
  within one standard error (over folds) of the best order's (the one-standard-error
  rule: a higher order must earn its keep).
- Limits: the CV tells a true curvature from WHITE bin noise reliably (the tests), but
  slow 1/f bias wander during a single cool-down maps onto P like a curvature would,
  and then a higher order can honestly win. Repeat the run, or cap --max-order (the
  thesis used order 1), when the orders' CV errors are close.
- Fit the chosen order by least squares (numpy Polynomial.fit on a scaled domain,
  converted back to powers of P in degrees).
- The same against a temperature column (t_board_c by default) for comparison: the
  residual bias stability (std and peak-to-peak of bias - fit, deg/s) of each says
  which compensation variable is better (fig. 7-13).
- Optional spike removal (the thesis removed "small spikes" before fitting): bins whose
  residual exceeds K robust standard deviations (1.4826 MAD) are dropped and the fit
  repeated once.

Scale factor against P (optional, from a rate-table run at several temperatures): per
constant-rate segment the mean output, table rate and mean P; then
    out = sum_a b_a P^a + rate_in * sum_j s_j P^j
with the bias order of the bias fit and the scale-factor order by blocked CV over
segments. Reported as s_j and normalised as SF(P)/SF(0) = 1 + r1 P + r2 P^2 + r3 P^3.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from numpy.polynomial import Polynomial

from .errors import InputError

MAX_ORDER = 3
MAD_TO_SIGMA = 1.4826
# Least span of the thermometer, in its bin-to-bin scatter, for a fit against it: noise
# alone spans about 6 scatters over a few hundred bins.
MIN_SPAN_PER_SCATTER = 20.0


def bin_average(t_s, columns, bin_s):
    """Means over contiguous time bins of width bin_s: dict like columns plus 't_s'."""
    t_s = np.asarray(t_s, dtype=float)
    if not bin_s > 0:
        raise InputError(f"bin width {bin_s} s must be > 0")
    idx = np.floor((t_s - t_s[0]) / bin_s).astype(np.int64)
    _, inv, counts = np.unique(idx, return_inverse=True, return_counts=True)
    out = {"t_s": np.bincount(inv, weights=t_s) / counts}
    for name, v in columns.items():
        out[name] = np.bincount(inv, weights=np.asarray(v, dtype=float)) / counts
    return out


def poly_fit(x, y, order):
    """Ascending coefficients in powers of raw x, fitted on a scaled domain."""
    if order == 0:
        return np.array([float(np.mean(y))])
    p = Polynomial.fit(x, y, order).convert()
    c = np.zeros(order + 1)
    c[:p.coef.size] = p.coef
    return c


def poly_eval(c, x):
    return Polynomial(c)(np.asarray(x, dtype=float))


# The firmware's bias polynomial, c0..c3 (firmware/params/param_list.h).
BIAS_PARAMS = ("rate.bias_c0_dps", "rate.bias_c1_dps_per_deg", "rate.bias_c2_dps_per_deg2",
               "rate.bias_c3_dps_per_deg3")


def firmware_bias(fit):
    """The firmware's values for a bias fit in absolute P: the polynomial in the deviation
    x = P - ref from the middle of the fitted span (cal.ref_p_deg, rate_channel.c), the
    thermometer range half that span (rate.p_range_deg: the rate is valid only where the
    fit had data), and no gradient term (a fit of its own, tools/calibrate)."""
    lo, hi = fit.x_range
    ref = 0.5 * (lo + hi)
    c = padded(Polynomial(fit.coeffs)(Polynomial([ref, 1.0])).coef)
    v = dict(zip(BIAS_PARAMS, (float(x) for x in c)))
    v.update({"cal.ref_p_deg": float(ref), "rate.p_range_deg": float(max(0.5 * (hi - lo), 1e-3)),
              "rate.bias_grad_dps_per_deg": 0.0})
    return v


def blocks(n, k):
    """k contiguous index blocks covering 0..n-1."""
    edges = np.linspace(0, n, k + 1).round().astype(int)
    return [np.arange(a, b) for a, b in zip(edges[:-1], edges[1:])]


def blocked_cv(x, y, k=5, max_order=MAX_ORDER, fitter=None):
    """Per order: (cv_mse, se) over k contiguous blocks; fitter(train_idx, order) ->
    predict(test_idx) for models other than a plain polynomial in x."""
    n = len(y)
    if fitter is None:
        def fitter(tr, order):
            c = poly_fit(x[tr], y[tr], order)
            return lambda te: poly_eval(c, x[te])
    folds = blocks(n, k)
    mse, se = [], []
    for order in range(max_order + 1):
        fold_mse = []
        sse = 0.0
        for te in folds:
            tr = np.setdiff1d(np.arange(n), te)
            pred = fitter(tr, order)(te)
            e = y[te] - pred
            fold_mse.append(float(np.mean(e ** 2)))
            sse += float(np.sum(e ** 2))
        mse.append(sse / n)
        se.append(float(np.std(fold_mse, ddof=1) / math.sqrt(len(folds))))
    return np.array(mse), np.array(se)


def choose_order(mse, se):
    """Lowest order within one standard error of the best (see module doc)."""
    best = int(np.argmin(mse))
    limit = mse[best] + se[best]
    return int(np.flatnonzero(mse <= limit)[0])


@dataclasses.dataclass
class PolyFit:
    variable: str
    order: int
    coeffs: np.ndarray          # ascending, length order + 1
    cv_rmse: np.ndarray         # per order 0..max_order
    cv_se_mse: np.ndarray
    residual: np.ndarray        # on the kept bins
    kept: np.ndarray            # bool mask of bins used
    residual_std: float
    residual_p2p: float
    x_range: tuple


def fit_bias(x, y, variable, k=10, max_order=MAX_ORDER, despike=None):
    """Blocked-CV polynomial of y (deg/s) against x; see module doc."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    n = y.size
    max_order = min(max_order, MAX_ORDER)
    need = k * (max_order + 2)
    if n < need:
        raise InputError(f"{n} bins; a {k}-fold fit up to order {max_order} needs at least "
                         f"{need} (use a longer log or a shorter --bin)")
    if np.ptp(x) == 0:
        raise InputError(f"{variable} does not change over the log: nothing to fit against")
    # The thermometer's span against its own bin-to-bin scatter (the spread of its first
    # differences, which a trend does not have): an isothermal log's P is its noise, and a
    # fit of the bias against it is noise against noise.
    scatter = float(np.std(np.diff(x))) / math.sqrt(2.0)
    if np.ptp(x) < MIN_SPAN_PER_SCATTER * scatter:
        raise InputError(f"{variable} spans {np.ptp(x):.3g} over the log, "
                         f"{np.ptp(x) / scatter:.1f} times its bin-to-bin scatter "
                         f"({scatter:.3g}): no temperature change to fit against (an "
                         "isothermal log?); need at least "
                         f"{MIN_SPAN_PER_SCATTER:g} times")
    kept = np.ones(n, dtype=bool)
    mse, se = blocked_cv(x, y, k=k, max_order=max_order)
    order = choose_order(mse, se)
    c = poly_fit(x, y, order)
    if despike:
        r = y - poly_eval(c, x)
        mad = float(np.median(np.abs(r - np.median(r))))
        new = np.abs(r - np.median(r)) <= despike * MAD_TO_SIGMA * max(mad, 1e-300)
        if not new.all() and np.count_nonzero(new) >= need:
            kept = new
            mse, se = blocked_cv(x[kept], y[kept], k=k, max_order=max_order)
            order = choose_order(mse, se)
            c = poly_fit(x[kept], y[kept], order)
    resid = y[kept] - poly_eval(c, x[kept])
    return PolyFit(variable=variable, order=order, coeffs=c, cv_rmse=np.sqrt(mse),
                   cv_se_mse=se, residual=resid, kept=kept,
                   residual_std=float(np.std(resid, ddof=1)),
                   residual_p2p=float(np.ptp(resid)),
                   x_range=(float(x.min()), float(x.max())))


@dataclasses.dataclass
class SfFit:
    bias_order: int
    sf_order: int
    bias_coeffs: np.ndarray
    sf_coeffs: np.ndarray       # out per deg/s, ascending in P
    sf_rel_coeffs: np.ndarray   # SF(P)/SF(0): [1, r1, r2, r3]
    cv_rmse: np.ndarray
    residual_rms: float
    n_segments: int


def fit_sf(rate_in, mean_out, mean_p, bias_order, k=5, max_order=MAX_ORDER):
    """Joint bias(P) + rate * SF(P) fit over rate-table segments (see module doc)."""
    r = np.asarray(rate_in, dtype=float)
    y = np.asarray(mean_out, dtype=float)
    p = np.asarray(mean_p, dtype=float)
    n = y.size
    if np.unique(r).size < 2:
        raise InputError("the scale-factor log needs at least two table rates")
    k = max(2, min(k, n // 3))
    if n < k * (bias_order + 2):
        raise InputError(f"{n} rate-table segments are too few for a scale-factor fit "
                         "against P")
    scale = max(float(np.max(np.abs(p))), 1e-12)  # conditioning only

    def design(idx, order):
        ps = p[idx] / scale
        cols = [ps ** a for a in range(bias_order + 1)]
        cols += [r[idx] * ps ** j for j in range(order + 1)]
        return np.column_stack(cols)

    def fitter(tr, order):
        coef, *_ = np.linalg.lstsq(design(tr, order), y[tr], rcond=None)
        return lambda te: design(te, order) @ coef

    max_order = max(0, min(max_order, (n - n // k) - bias_order - 3))
    mse, se = blocked_cv(p, y, k=k, max_order=max_order, fitter=fitter)
    order = choose_order(mse, se)
    allidx = np.arange(n)
    coef, *_ = np.linalg.lstsq(design(allidx, order), y, rcond=None)
    pw = scale ** np.arange(max(bias_order, order) + 1)
    b = coef[:bias_order + 1] / pw[:bias_order + 1]
    s = coef[bias_order + 1:] / pw[:order + 1]
    resid = y - design(allidx, order) @ coef
    return SfFit(bias_order=bias_order, sf_order=order, bias_coeffs=b, sf_coeffs=s,
                 sf_rel_coeffs=s / s[0], cv_rmse=np.sqrt(mse),
                 residual_rms=float(np.sqrt(np.mean(resid ** 2))), n_segments=n)


def padded(c, n=MAX_ORDER + 1):
    out = np.zeros(n)
    out[:len(c)] = c
    return out


def fit_summary(fit, unit_x):
    return {
        "variable": fit.variable,
        "order": fit.order,
        "coeffs": padded(fit.coeffs).tolist(),
        "coeffs_definition": f"bias_dps = c0 + c1 x + c2 x^2 + c3 x^3, x = {fit.variable} "
                             f"({unit_x})",
        "cv_rmse_dps_by_order": fit.cv_rmse.tolist(),
        "cv_standard_error_mse_by_order": fit.cv_se_mse.tolist(),
        "residual_std_dps": fit.residual_std,
        "residual_p2p_dps": fit.residual_p2p,
        "bins_used": int(np.count_nonzero(fit.kept)),
        "bins_dropped_as_spikes": int(np.count_nonzero(~fit.kept)),
        "x_range": list(fit.x_range),
    }


def sf_summary(sf):
    return {
        "bias_order": sf.bias_order,
        "sf_order": sf.sf_order,
        "bias_coeffs_dps": padded(sf.bias_coeffs).tolist(),
        "sf_coeffs_out_per_dps": padded(sf.sf_coeffs).tolist(),
        "sf_coeffs_definition": "SF(P) = s0 + s1 P + s2 P^2 + s3 P^3 (output per deg/s)",
        "sf_rel_coeffs": padded(sf.sf_rel_coeffs).tolist(),
        "sf_rel_definition": "SF(P)/SF(0) = 1 + r1 P + r2 P^2 + r3 P^3",
        "cv_rmse_out_by_order": sf.cv_rmse.tolist(),
        "residual_rms_out": sf.residual_rms,
        "n_segments": sf.n_segments,
    }


def _scatter_fit(ax, x, y, fit, xlabel, name=""):
    from . import plotting

    xx = np.linspace(x.min(), x.max(), 200)
    ax.plot(x[fit.kept], y[fit.kept], ".", ms=3, label="bias (bin means)")
    if not fit.kept.all():
        ax.plot(x[~fit.kept], y[~fit.kept], "x", ms=4, color="C3", label="spikes dropped")
    terms = " ".join(f"{c:+.5g}" + ("" if i == 0 else f" x^{i}" if i > 1 else " x")
                     for i, c in enumerate(fit.coeffs))
    ax.plot(xx, poly_eval(fit.coeffs, xx), "-", color="k", lw=1,
            label=f"order {fit.order}: {terms}")
    plotting.finish(ax, title=(f"{name} bias against {fit.variable}: residual std "
                               f"{fit.residual_std:.3g} deg/s, p-p {fit.residual_p2p:.3g} deg/s").lstrip(),
                    xlabel=xlabel, ylabel="bias (deg/s)")


def plots(binned, y_col, p_fit, t_fit, out_dir, sf=None, sf_segments=None, name=""):
    """Bias vs P, bias vs T, residual vs time (fig. 7-13..7-17); SF vs P if fitted."""
    from . import plotting

    paths = []
    fig, ax = plotting.figure()
    _scatter_fit(ax, binned[p_fit.variable], binned[y_col], p_fit, "drive phase P (deg)", name)
    paths.append(plotting.save(fig, out_dir, "tempcomp_bias_vs_p.png"))
    if t_fit is not None:
        fig, ax = plotting.figure()
        _scatter_fit(ax, binned[t_fit.variable], binned[y_col], t_fit,
                     f"{t_fit.variable} (degC)", name)
        paths.append(plotting.save(fig, out_dir, "tempcomp_bias_vs_t.png"))
    fig, (a1, a2) = plotting.figure(2, 1, height_in=3.2, sharex=True)
    t = binned["t_s"]
    a1.plot(t, binned[y_col], "-", lw=0.8, label="bias")
    a1b = a1.twinx()
    a1b.plot(t, binned[p_fit.variable], "-", lw=0.8, color="C1")
    a1b.set_ylabel("P (deg)", color="C1")
    a1.plot([], [], "-", lw=0.8, color="C1", label="drive phase P (right axis)")
    plotting.finish(a1, title=f"bias and drive phase during the log {name}".rstrip(),
                    ylabel="bias (deg/s)")
    a2.plot(t[p_fit.kept], p_fit.residual, "-", lw=0.8,
            label=f"compensated with P: std {p_fit.residual_std:.3g} deg/s")
    if t_fit is not None:
        a2.plot(t[t_fit.kept], t_fit.residual, "-", lw=0.8,
                label=f"compensated with {t_fit.variable}: std {t_fit.residual_std:.3g}")
    plotting.finish(a2, title="residual bias after compensation", xlabel="time (s)",
                    ylabel="residual (deg/s)")
    paths.append(plotting.save(fig, out_dir, "tempcomp_residual.png"))
    if sf is not None and sf_segments is not None:
        fig, ax = plotting.figure()
        ps = np.array([s["p_deg"] for s in sf_segments])
        rs = np.array([s["rate_in_dps"] for s in sf_segments])
        ys = np.array([s["mean_out"] for s in sf_segments])
        nz = rs != 0
        bias = poly_eval(sf.bias_coeffs, ps[nz])
        ax.plot(ps[nz], (ys[nz] - bias) / rs[nz], "o", ms=3,
                label="(out - bias(P)) / rate per segment")
        xx = np.linspace(ps.min(), ps.max(), 100)
        ax.plot(xx, poly_eval(sf.sf_coeffs, xx), "-", color="k", lw=1,
                label=f"SF(P), order {sf.sf_order}")
        plotting.finish(ax, title="scale factor against P", xlabel="drive phase P (deg)",
                        ylabel="scale factor (out per deg/s)")
        paths.append(plotting.save(fig, out_dir, "tempcomp_sf_vs_p.png"))
    return paths
