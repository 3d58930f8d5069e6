"""Scale factor from a rate-table log (thesis 7.2.4 item 1, table 7-2, fig. 7-9).

The table turns at constant rates, CW and CCW (the thesis: +-20..160 deg/s in 20 deg/s
steps). Per constant-rate segment the output is averaged after a settling time; then

    out = bias + SF * rate_in                 least squares over the segment means
    residual_in = (out - fit) / SF            input-referred residual, deg/s
    nonlinearity = RMS(residual_in) / FS      FS = the largest |rate_in| applied, ONE
                                              side (the thesis: 0.5572 / 160 = 0.348 %)
    SF+ , SF-  least-squares slopes of the rate >= 0 and rate <= 0 segments, each
               with its own intercept (zero-rate segments belong to both);
               asymmetry = (SF+ - SF-) / ((SF+ + SF-) / 2)

(The thesis's 0.5572 deg/s is the residual standard deviation with n - 1 over its eight
half-difference points; the RMS here divides by n.) The thesis averaged CW and CCW to
cancel the bias, (out(+r) - out(-r)) / 2; those half differences are reported as well.

Segments come from rate_true_dps when the log has it (gyro-sim): runs where it is
constant. A `gyroctl` log of real hardware has no truth column: then the table schedule
is given as a list of (rate deg/s, dwell s) starting at t0, e.g.
"0:10,20:10,-20:10,40:10,-40:10"; t0 is found from the step edges (align_table: the lag
at which the schedule correlates best with the output) unless given.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import signal

from .errors import InputError

MIN_SEGMENTS = 3


# Default segmentation of a rate table: 0.5 s excluded after each step (the 100 Hz output
# settles in 20 ms, a table's acceleration, the project's 0.1 s edges, well within it),
# then at least 0.5 s averaged: fits the project's own rate tables (1.5 s dwell, as the
# thesis's 7.2.4) and longer ones.
SETTLE_S_DEFAULT = 0.5
MIN_AVG_S_DEFAULT = 0.5

@dataclasses.dataclass
class Segment:
    rate_in_dps: float
    t_start_s: float        # averaging window actually used (after settling)
    t_end_s: float
    n: int
    mean_out: float
    std_out: float
    mean_p_deg: float = float("nan")


def parse_table(text):
    """'r1:d1,r2:d2,...' (deg/s : s) -> [(rate_dps, dwell_s), ...]."""
    out = []
    for item in str(text).replace(";", ",").split(","):
        item = item.strip()
        if not item:
            continue
        parts = item.split(":")
        if len(parts) != 2:
            raise InputError(f"rate table entry '{item}' is not RATE:DWELL")
        try:
            r, d = float(parts[0]), float(parts[1])
        except ValueError:
            raise InputError(f"rate table entry '{item}' is not two numbers") from None
        if not (math.isfinite(r) and math.isfinite(d) and d > 0):
            raise InputError(f"rate table entry '{item}': dwell must be > 0 s")
        out.append((r, d))
    if not out:
        raise InputError("empty rate table")
    return out


def windows_from_truth(t_s, rate_true_dps, settle_s, min_avg_s, tol_dps=1e-6):
    """(rate, i0, i1) averaging windows: runs of constant rate_true, settling excluded."""
    t_s = np.asarray(t_s, dtype=float)
    r = np.asarray(rate_true_dps, dtype=float)
    change = np.flatnonzero(np.abs(np.diff(r)) > tol_dps) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change, [r.size]])
    out = []
    for s, e in zip(starts, ends):
        i0 = s + int(np.searchsorted(t_s[s:e], t_s[s] + settle_s))
        if e - i0 < 2 or t_s[e - 1] - t_s[i0] < min_avg_s:
            continue
        out.append((float(np.median(r[s:e])), int(i0), int(e)))
    return out


def windows_from_table(t_s, table, t0_s, settle_s, min_avg_s):
    """(rate, i0, i1) averaging windows from a schedule [(rate, dwell)] starting at t0."""
    t_s = np.asarray(t_s, dtype=float)
    total = sum(d for _, d in table)
    if t0_s > t_s[-1] or t0_s + total < t_s[0]:
        raise InputError(f"the rate table schedule ({t0_s:g}..{t0_s + total:g} s) does not "
                         f"overlap the log ({t_s[0]:g}..{t_s[-1]:g} s)")
    out = []
    t = t0_s
    for rate, dwell in table:
        lo, hi = t + settle_s, t + dwell
        i0, i1 = int(np.searchsorted(t_s, lo)), int(np.searchsorted(t_s, hi))
        t = hi
        if i1 - i0 < 2 or t_s[i1 - 1] - t_s[i0] < min_avg_s:
            continue
        out.append((float(rate), i0, i1))
    return out


# Auto-alignment: the schedule's correlation with the output at the best lag below this is
# no alignment (a table with the wrong schedule, or a log of something else).
ALIGN_MIN_CORR = 0.9


def schedule_wave(table, dt_s):
    """The schedule's rate at steps of dt_s from its start."""
    return np.concatenate([np.full(max(1, int(round(d / dt_s))), float(r)) for r, d in table])


def align_table(t_s, out, table, signed=True):
    """(t0, correlation): where the schedule [(rate, dwell)] starts in the log, from the
    step edges: the lag at which the schedule's rate correlates best with the output (the
    output is bias + SF rate + noise; its lag to the table is the 100 Hz output's few ms).
    The whole schedule must lie in the log. signed=False: the output's sign is unknown
    (the strongest correlation of either sign)."""
    t_s = np.asarray(t_s, dtype=float)
    dt = float(np.median(np.diff(t_s)))
    wave = schedule_wave(table, dt)
    y = np.asarray(out, dtype=float)
    if wave.size > y.size:
        raise InputError(f"record too short to align the table: {t_s[-1] - t_s[0]:.4g} s of "
                         f"log, the schedule lasts {sum(d for _, d in table):.4g} s "
                         "(give --t0, or a log of the whole table)")
    w = wave - wave.mean()
    if not np.any(w):
        raise InputError("the table schedule has one rate only: nothing to align on")
    num = signal.correlate(y - y.mean(), w, mode="valid")
    k = int(np.argmax(num if signed else np.abs(num)))
    seg = y[k:k + w.size]
    corr = float(np.corrcoef(seg, w)[0, 1]) if np.std(seg) > 0 else 0.0
    corr = corr if signed else abs(corr)
    if not corr >= ALIGN_MIN_CORR:
        raise InputError(f"cannot align the table schedule with the log (best correlation "
                         f"{corr:.3f} at {t_s[k]:.4g} s, below {ALIGN_MIN_CORR:g}): check "
                         "--table, or give --t0")
    return float(t_s[k]), corr


def segment_means(t_s, out, windows, p_deg=None, valid=None):
    """Averages of out (and P) over each window; with valid (a boolean per sample) over its
    valid samples only, a window without any left out (an analog output at its fault
    level is no reading of the rate)."""
    segs = []
    for rate, i0, i1 in windows:
        keep = np.ones(i1 - i0, dtype=bool) if valid is None else np.asarray(valid[i0:i1], bool)
        if not keep.any():
            continue
        y = out[i0:i1][keep]
        segs.append(Segment(rate_in_dps=rate, t_start_s=float(t_s[i0]),
                            t_end_s=float(t_s[i1 - 1]), n=int(keep.sum()),
                            mean_out=float(np.mean(y)), std_out=float(np.std(y)),
                            mean_p_deg=float(np.mean(p_deg[i0:i1][keep])) if p_deg is not None
                            else float("nan")))
    return segs


@dataclasses.dataclass
class ScaleFactorResult:
    segments: list
    sf: float                   # output units per input deg/s
    bias: float                 # output units
    residual_in_dps: np.ndarray
    rms_residual_dps: float
    max_residual_dps: float
    full_scale_dps: float
    nonlinearity: float         # fraction of full scale
    sf_pos: float
    sf_neg: float
    asymmetry: float
    half_differences: list      # [(|rate|, (out(+r) - out(-r)) / 2)]


def fit(rate_in_dps, mean_out, segments=None):
    """Least-squares line and the figures of the module doc."""
    x = np.asarray(rate_in_dps, dtype=float)
    y = np.asarray(mean_out, dtype=float)
    if x.size < MIN_SEGMENTS or np.unique(x).size < 2:
        raise InputError(f"{np.unique(x).size} distinct table rates; the scale factor needs "
                         f"at least {MIN_SEGMENTS} segments at 2 or more rates")
    a = np.column_stack([np.ones_like(x), x])
    (bias, sf), *_ = np.linalg.lstsq(a, y, rcond=None)
    if sf == 0:
        raise InputError("the output does not change with the table rate (slope 0)")
    if sf < 0:
        raise InputError(f"the fitted scale factor is negative ({sf:.4g}): the table's "
                         "schedule is probably misaligned with the log (--t0), or the "
                         "output's sign is reversed")
    res_in = (y - (bias + sf * x)) / sf
    fs = float(np.max(np.abs(x)))
    if fs == 0:
        raise InputError("no non-zero table rate")
    rms = float(np.sqrt(np.mean(res_in ** 2)))

    def side(mask):
        """Slope of its own least-squares line over one side (zero-rate points shared)."""
        if np.unique(x[mask]).size < 2:
            return math.nan
        return float(np.polynomial.polynomial.polyfit(x[mask], y[mask], 1)[1])

    sf_pos, sf_neg = side(x >= 0), side(x <= 0)
    asym = (sf_pos - sf_neg) / ((sf_pos + sf_neg) / 2.0)
    halves = []
    for r in np.unique(np.abs(x[x > 0])):
        pos, neg = y[np.isclose(x, r)], y[np.isclose(x, -r)]
        if pos.size and neg.size:
            halves.append((float(r), float((pos.mean() - neg.mean()) / 2.0)))
    return ScaleFactorResult(
        segments=segments or [], sf=float(sf), bias=float(bias), residual_in_dps=res_in,
        rms_residual_dps=rms, max_residual_dps=float(np.max(np.abs(res_in))),
        full_scale_dps=fs, nonlinearity=rms / fs, sf_pos=sf_pos, sf_neg=sf_neg,
        asymmetry=float(asym), half_differences=halves)


def analyse(t_s, out, rate_true_dps=None, table=None, t0_s=None, settle_s=1.0,
            min_avg_s=1.0, valid=None):
    """Segment the log (truth column, else the table schedule), average and fit."""
    t_s = np.asarray(t_s, dtype=float)
    out = np.asarray(out, dtype=float)
    if rate_true_dps is not None:
        win = windows_from_truth(t_s, rate_true_dps, settle_s, min_avg_s)
    elif table is not None:
        if t0_s is None:
            t0_s, _ = align_table(t_s, out, table)
        win = windows_from_table(t_s, table, t0_s, settle_s, min_avg_s)
    else:
        raise InputError("the log has no rate_true_dps column: give the table schedule "
                         "(--table RATE:DWELL,...)")
    if len(win) < MIN_SEGMENTS:
        raise InputError(f"found {len(win)} constant-rate segments longer than settle "
                         f"{settle_s:g} s + {min_avg_s:g} s; need at least {MIN_SEGMENTS}")
    segs = segment_means(t_s, out, win, valid=valid)
    return fit([s.rate_in_dps for s in segs], [s.mean_out for s in segs], segs)


def summary(res, out_unit="deg/s"):
    return {
        "out_unit": out_unit,
        "scale_factor_out_per_dps": res.sf,
        "bias_out": res.bias,
        "bias_definition": "output at zero input rate from the least-squares line",
        "rms_residual_dps": res.rms_residual_dps,
        "max_abs_residual_dps": res.max_residual_dps,
        "full_scale_dps": res.full_scale_dps,
        "full_scale_definition": "largest |table rate| applied (one side, as the thesis)",
        "nonlinearity_rms_fraction_of_fs": res.nonlinearity,
        "nonlinearity_rms_percent_of_fs": 100.0 * res.nonlinearity,
        "nonlinearity_max_percent_of_fs": 100.0 * res.max_residual_dps / res.full_scale_dps,
        "scale_factor_pos_out_per_dps": res.sf_pos,
        "scale_factor_neg_out_per_dps": res.sf_neg,
        "asymmetry_fraction": res.asymmetry,
        "asymmetry_definition": "(SF+ - SF-) / mean(SF+, SF-); SF+- = slope of the "
                                "rate >= 0 / rate <= 0 segments, own intercepts",
        "half_differences": [{"rate_dps": r, "half_difference_out": h}
                             for r, h in res.half_differences],
        "segments": [dataclasses.asdict(s) | {"residual_dps": float(r)}
                     for s, r in zip(res.segments, res.residual_in_dps)],
    }


def plot(res, out_dir, name="scalefactor.png", title="", out_unit="deg/s"):
    """Output against table rate with the fit, and input-referred residuals (fig. 7-9)."""
    from . import plotting

    x = np.array([s.rate_in_dps for s in res.segments])
    y = np.array([s.mean_out for s in res.segments])
    fig, (ax1, ax2) = plotting.figure(2, 1, height_in=3.3, sharex=True)
    xx = np.linspace(x.min(), x.max(), 2)
    ax1.plot(x, y, "o", ms=4, label="segment means")
    ax1.plot(xx, res.bias + res.sf * xx, "-", lw=1,
             label=f"SF = {res.sf:.6g} {out_unit}/(deg/s), bias = {res.bias:.4g} {out_unit}")
    plotting.finish(ax1, title=title or "Scale factor", ylabel=f"output ({out_unit})")
    order = np.argsort(x, kind="stable")
    ax2.plot(x[order], res.residual_in_dps[order], "o-", ms=4, lw=0.8)
    ax2.axhline(0, color="k", lw=0.6)
    ax2.lines[-2].set_label("residual per segment")
    for s in (-1, 1):
        ax2.axhline(s * res.rms_residual_dps, ls="--", color="C1", lw=0.8,
                    label="+-RMS residual" if s > 0 else None)
    plotting.finish(ax2, title=f"nonlinearity {100 * res.nonlinearity:.3g} % of FS "
                    f"{res.full_scale_dps:g} deg/s (RMS {res.rms_residual_dps:.3g} deg/s)",
                    xlabel="table rate (deg/s)", ylabel="residual (deg/s, input)")
    return plotting.save(fig, out_dir, name)
