"""The figures of the IEEE 1431 report's series (gyrotools/ieee1431.py, whose doc gives
their definitions), each from one verification log (csvlog.Log) by the analyses the
flow already has: scalefactor.fit, allan.analyse and allan.ieee952, thermcal's plateau
windows and ramp bins. InputError, naming the log, where a log cannot give a figure."""

from __future__ import annotations

import dataclasses

import numpy as np

from . import allan, calflow, csvlog, fields, lincal, scalefactor, tempcomp, thermcal
from .errors import InputError

SELFTEST_BIT = 1 << fields.RATE_INVALID.index("SELFTEST")
# The truth temperatures (the simulator's); a structure temperature is reported only
# where it was logged.
TEMPERATURES = ("t_ambient_c", "t_struct_c")
# turn_on.png shows the first moments: this many times the later of the two turn-on
# figures (the air part's 0.15 s, a Q 3e4 part's some 30 s), at least the minimum, within
# the rest.
TURN_ON_PLOT_MIN_S = 0.5
# A structure that moves less than this over the rate table's run has not warmed up.
WARM_UP_STILL_K = 0.05
TURN_ON_PLOT_TIMES = 4.0


settled_time = thermcal.settled_time


def power_on_rest(log):
    """Index where the power-on rest ends: the input's first move or the self-test's
    start, whichever is first (the end of the log if neither)."""
    moved = np.flatnonzero(np.abs(log["rate_true_dps"]) > 1e-9)
    test = np.flatnonzero(log["rate_invalid"].astype(np.int64) & SELFTEST_BIT)
    ends = [a[0] for a in (moved, test) if a.size] + [len(log)]
    return int(min(ends))


def turn_on(log, bound_dps):
    """12.5: the turn-on figures of a log that starts at power-on, at rest."""
    end = power_on_rest(log)
    if end < 2:
        raise InputError(f"{log.path}: the input moves at power-on: no rest to read the "
                         "turn-on time on")
    t, out, truth = log["t_s"][:end], log["rate_dps"][:end], log["rate_true_dps"][:end]
    valid = log["rate_valid"][:end] > 0.5
    t_on = settled_time(t, valid)
    t_in = settled_time(t, np.abs(out - truth) <= bound_dps)
    first = np.flatnonzero(valid)
    figs = {"rest_after_power_on_s": float(t[-1]), "error_bound_dps": bound_dps,
            "turn_on_time_s": t_on, "time_to_error_bound_s": t_in,
            "first_valid_sample_s": float(t[first[0]]) if first.size else None,
            "drive_locked_s": calflow.lock_time_s(log),
            "invalid_s_by_reason_in_rest": fields.invalid_time_s(t, log["rate_invalid"][:end])}
    if t_on is None:
        figs["turn_on_note"] = (f"not valid for good within the {t[-1]:.3g} s at rest "
                                "after power-on")
    if "t_struct_c" in log:
        figs["warm_up"] = warm_up(log["t_struct_c"])
    return figs


def warm_up(t_struct_c):
    """What the structure's temperature did over the turn-on run: 12.6's warm-up time is
    measured on a cold start of its own (the warm_up series), not on this run."""
    moved = float(t_struct_c[-1] - t_struct_c[0])
    why = (f"the structure's temperature stays within {WARM_UP_STILL_K:g} K over the run: the part starts "
           "at its own thermal equilibrium"
           if abs(moved) < WARM_UP_STILL_K else
           f"the structure's temperature moves {moved:+.2f} K over the run")
    return {"t_struct_c_at_power_on": float(t_struct_c[0]),
            "t_struct_c_at_end": float(t_struct_c[-1]), "note": why + "; 12.6 warm-up time: "
            "the warm_up series (a cold start)"}


def turn_on_window(log, figs):
    """The rows turn_on.png shows: the first seconds (TURN_ON_PLOT_*), within the rest."""
    later = max([x for x in (figs["turn_on_time_s"], figs["time_to_error_bound_s"])
                 if x is not None] or [figs["rest_after_power_on_s"]])
    t_max = min(figs["rest_after_power_on_s"],
                max(TURN_ON_PLOT_MIN_S, TURN_ON_PLOT_TIMES * later))
    return log["t_s"] <= t_max


def rate_transfer(log):
    """The held means (valid samples, before the self-test): (the rates', each against
    the rests around it and shifted to the rests' mean level, as scalefactor.Segment
    list; the rests' own)."""
    t = log["t_s"]
    test = np.flatnonzero(log["rate_invalid"].astype(np.int64) & SELFTEST_BIT)
    keep = (log["rate_valid"] > 0.5) & (t < (t[test[0]] if test.size else np.inf))
    t, out, truth = t[keep], log["rate_dps"][keep], log["rate_true_dps"][keep]
    win = scalefactor.windows_from_truth(t, truth, calflow.SETTLE_S, calflow.MIN_AVG_S)
    segs = scalefactor.segment_means(t, out, win)
    r = np.array([s.rate_in_dps for s in segs])
    m = np.array([s.mean_out for s in segs])
    rest = r == 0.0
    if not rest.any() or rest.all():
        raise InputError(f"{log.path}: no held rests and rates to measure the rates "
                         "against")
    # The bias's wander between the rests around each rate taken out (a flicker of
    # 0.01 deg/s between means is 180 ppm over 80 deg/s), its level kept for the fit's
    # bias. The rests stay out of the fit: their scatter is that wander, not the line's.
    m = m - lincal.bias_between_rests(r, m) + np.mean(m[rest])
    rates = [dataclasses.replace(s, mean_out=float(y)) for s, y, z in zip(segs, m, rest) if not z]
    return rates, [s for s, z in zip(segs, rest) if z]


def scale_factor(log):
    """12.9: (scalefactor result, figures) over the verification's rate table."""
    segs, rests = rate_transfer(log)
    res = scalefactor.fit([s.rate_in_dps for s in segs], [s.mean_out for s in segs], segs)
    at_rest = np.array([s.mean_out for s in rests])
    figs = {"scale_factor_dps_per_dps": res.sf, "scale_factor_error_ppm": (res.sf - 1.0) * 1e6,
            "bias_dps": res.bias, "full_scale_dps": res.full_scale_dps,
            "bias_at_rest_mean_dps": float(np.mean(at_rest)),
            "bias_at_rest_std_dps": float(np.std(at_rest)),
            "nonlinearity_rms_percent_fs": 100.0 * res.nonlinearity,
            "nonlinearity_max_percent_fs": 100.0 * res.max_residual_dps / res.full_scale_dps,
            "residual_rms_dps": res.rms_residual_dps,
            "scale_factor_pos_dps_per_dps": res.sf_pos,
            "scale_factor_neg_dps_per_dps": res.sf_neg,
            "asymmetry_ppm": res.asymmetry * 1e6,
            "held_means": [{"rate_in_dps": s.rate_in_dps, "mean_out_dps": s.mean_out,
                            "residual_in_dps": float(e), "samples": s.n}
                           for s, e in zip(segs, res.residual_in_dps)],
            "rests": [{"t_mid_s": 0.5 * (s.t_start_s + s.t_end_s), "mean_out_dps": s.mean_out,
                       "samples": s.n} for s in rests]}
    return res, figs


def drift(log):
    """12.11: the 1 s means and Allan deviations of rate_dps and rate_unc_dps from
    thermcal.START_S on: (figures, {column: allan result}, 1 s means)."""
    t = log["t_s"]
    m = t >= thermcal.START_S
    if np.count_nonzero(m) < allan.MIN_SAMPLES:
        raise InputError(f"{log.path}: {np.count_nonzero(m)} rows after the start-up "
                         f"({thermcal.START_S:g} s); the Allan deviation needs "
                         f"{allan.MIN_SAMPLES}")
    fs = csvlog.sample_rate_hz(t[m], path=log.path)
    cols = ("rate_dps", "rate_unc_dps")
    res = {c: allan.analyse(log[c][m], fs) for c in cols}
    means = tempcomp.bin_average(t[m], {c: log[c][m] for c in cols}, thermcal.BIN_S)
    figs = {"from_s": thermcal.START_S, "record_s": float(t[m][-1] - t[m][0]),
            "sample_rate_hz": fs}
    for c in cols:
        s = allan.summary(res[c])
        figs[c] = {"mean_dps": float(np.mean(log[c][m])),
                   "means_1s_std_dps": float(np.std(means[c])),
                   "ieee952": allan.ieee952(res[c]),
                   "adev_at_1s_dph": s["adev_at_1s_dph"],
                   "adev_min_measured_dph": s["adev_min_measured_dph"],
                   "tau_at_min_measured_s": s["tau_at_min_measured_s"],
                   "allan": {k: s[k] for k in ("tau_s", "adev_dph", "adev_ci68_lo_dph",
                                                "adev_ci68_hi_dph")}}
    figs["means_1s"] = {"t_s": means["t_s"], **{c: means[c] for c in cols}}
    return figs, res, means


def with_struct(log):
    """The log with a t_struct_c column: NaN where the log has none (real hardware), so
    that thermcal's plateau figures need not know."""
    if "t_struct_c" in log:
        return log
    from numpy.lib import recfunctions
    data = recfunctions.append_fields(log.data, "t_struct_c", np.full(len(log), np.nan),
                                      usemask=False)
    return dataclasses.replace(log, data=data)


def plateaus(log, proto):
    """12.8 at the verification's plateaus: thermcal.verify_plateaus's rows."""
    temps = proto.verify_plateaus_c
    need_s = len(temps) * proto.dwell_s - thermcal.TAIL_S
    if log["t_s"][-1] < need_s:
        raise InputError(f"{log.path}: ends at {log['t_s'][-1]:.6g} s; the {len(temps)} "
                         f"plateaus of {proto.dwell_s:g} s need {need_s:g} s")
    rows = thermcal.verify_plateaus(with_struct(log), temps, proto.dwell_s)
    return {"dwell_s": proto.dwell_s, "limits": {"bias_dps": thermcal.LIMITS["plateau_bias_dps"],
                                                 "scale_factor_ppm": thermcal.LIMITS["sf_ppm"]},
            "plateaus": [{"ambient_c": r["ambient_c"], "t_struct_c": r["t_struct_c"],
                          "p_f_deg": r["p_deg"], "bias_dps": r["bias_dps"],
                          "scale_factor_error_ppm": r["sf_ppm"], "valid_fraction": r["valid"]}
                         for r in rows]}


def ramp(log, proto):
    """12.8 in a ramp: the 1 s bias means at rest (the verification's bins) with the
    logged temperatures, and the bias's slope against the structure's temperature (the
    ambient's where no structure temperature was logged)."""
    t_from, t_to, k_per_min, lead, _ = proto.ramp
    temps = [c for c in TEMPERATURES if c in log]
    if not temps:
        raise InputError(f"{log.path}: no temperature column ({', '.join(TEMPERATURES)})")
    bins, valid = thermcal.rest_bins(log, lead, log["t_s"][-1], ("rate_dps",) + tuple(temps))
    if bins["rate_dps"].size < 3:
        raise InputError(f"{log.path}: {bins['rate_dps'].size} valid 1 s means at rest after "
                         f"{lead:g} s; the ramp's series needs 3")
    x_col = temps[-1]  # t_struct_c when logged
    slope = float(np.polyfit(bins[x_col], bins["rate_dps"], 1)[0]) if np.ptp(bins[x_col]) > 0 \
        else float("nan")
    return {"from_c": t_from, "to_c": t_to, "k_per_min": k_per_min, "from_s": lead,
            "valid_fraction": valid, "bias_1s_std_dps": float(np.std(bins["rate_dps"])),
            "bias_1s_max_abs_dps": float(np.max(np.abs(bins["rate_dps"]))),
            f"bias_slope_dps_per_k_of_{x_col[2:-2]}": slope,
            "limit_bias_1s_std_dps": thermcal.LIMITS["ramp_bias_std_dps"],
            "means_1s": bins}
