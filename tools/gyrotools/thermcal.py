"""Thermal calibration and its verification (stages of tools/calibrate, gyrotools/calflow).

The thermometer is the drive phase P (thesis 7.3: "sensorless"); the firmware compensates

    rate = u SF(x) - B(x) - k_g h,    x = P_c - cal.ref_p_deg,  h = P_c - LP_tau(P_c)

(u the uncompensated output, linearised (lincal), P_c the thermometer P_f low-passed over
rate.comp_tau_s in rate.comp_stages stages, rate_channel.c; with a fast path, B and k_g h
blended with those of a second thermometer of one rate.comp_fast_tau_s stage, fast_path).
B is a cubic in x, SF a quartic; the gradient term k_g h stands for the
structure-to-circuit temperature difference of a transient: P and the bias weigh the two
nodes differently, so during a ramp the bias is off the plateaus' B(x) by an amount that
follows P's recent change, which h measures (rate.grad_tau_s).

Calibration run (one gyro-sim run, the part at rest but for short rate steps): chamber
plateaus over -40..85 degC (CAL_PLATEAUS_C, CAL_DWELL_S each, the chamber's 60 s edges);
near each plateau's end the rate steps +R, -R, +R (SF at that temperature), after a rest
window (the bias there). P is the thermometer less the rate's own turn of it
(rate.p_rate_deg_per_dps, measured on the rate table before). From the log:
- SF(x): 2R / (u(+R) - u(-R)) per plateau against the plateau's mean x, cubic, its
  constant folded into rate.scale_dps so that SF(0) = 1;
- B(x) and k_g (with tau from TAU_GRID_S, the smallest residual): least squares over the
  1 s means of the whole run at rest, plateaus and transitions alike, on y = u SF(x);
- the rate's turn of P (rate.p_rate_deg_per_dps, measured at room temperature) against
  x: P_f at +R against -R at each plateau, a line in x (rate.p_rate_c1_per_dps; its
  constant added to the room-temperature value);
- cal.ref_p_deg: the middle of the plateaus' P span; rate.p_range_deg: half that span
  plus P_RANGE_MARGIN (the rate is valid only where the fit had data);
  rate.p_slew_max_deg_s: P's span over the plateaus' temperature span x SLEW_MAX_K_PER_S.

On the tracking drive P is p_eq (drive_track.h): the tracked frequency's deviation,
(2Q/f0) rad per Hz, so every one of these is in the deviation of the frequency from the
stored reference (cal.ref_p_deg), whatever Q.

Verification on profiles the fit never saw, each with its own noise seed: other plateaus
(VERIFY_PLATEAUS_C, with rate steps: bias and SF there), a heating ramp 25 -> 65 degC at
2 K/min (the 1 s means of the bias), a fast transient (TRANSIENT: a heat gun and the room,
the 1 s means of the bias), a cold start (WARMUP: the warm-up time, verify_warmup), and
the output noise at constant temperature with
the compensation against without it (Allan deviation at 1 s and 10 s of rate_dps and
rate_unc_dps of the same run, verify_noise).
"""

from __future__ import annotations

import dataclasses

import allantools
import numpy as np
from scipy import stats
from scipy.signal import lfilter

from . import allan, tempcomp
from .errors import InputError

CAL_PLATEAUS_C = (25.0, -40.0, -10.0, 10.0, 40.0, 60.0, 85.0)
VERIFY_PLATEAUS_C = (-25.0, 0.0, 20.0, 50.0, 70.0)
# 2400 s: six structure time constants of the default part (400 s), its 65 K steps
# settle to 0.2 % (the fit does not need them settled: the gradient term takes the rest).
CAL_DWELL_S = 2400.0
CHAMBER_EDGE_S = 60.0
# The rate steps at a plateau's end: at rest (its last REST_AVG_S judged), then +R, -R, +R
# for STEP_S each (their last STEP_AVG_S judged; the two +R around the -R take out a
# drift of the bias that is still settling), then rest again.
STEP_RATE_DPS = 100.0
STEP_S = 60.0
STEP_AVG_S = 45.0
REST_AVG_S = 300.0
TAIL_S = 20.0
TABLE_EDGE_S = 0.5
# The gradient term's time constants tried; the part's own is the one that fits best.
TAU_GRID_S = (10.0, 15.0, 20.0, 30.0, 40.0, 60.0, 90.0, 120.0, 180.0, 300.0, 600.0)
P_RANGE_MARGIN = 0.05  # of the span, each side
# The thermometer's slew limit (rate.p_slew_max_deg_s), in temperature: P moving faster
# than the structure's temperature can is not temperature (a phase disturbance), and the
# rate is not valid. 0.65 K/s is the firmware default's 0.05 deg/s on the air part, far
# above any ramp a chamber or a vehicle makes; in P it is the part's own slope times this
# (25 deg/K on a Q 2e4 part's tracking thermometer, 0.08 deg/K on the air part's P).
SLEW_MAX_K_PER_S = 0.65
SLEW_MIN_DEG_S = 0.001  # the parameter's own lower limit
# The scale factor against x: a quartic (rate.sf_c4_per_deg4); the default part's peaks
# near room temperature, and a cubic through the seven plateaus leaves 390 ppm.
SF_ORDER = 4
# The compensation's thermometer P_c: P_f through three first-order low-passes of 15 s each
# (rate.comp_stages, rate.comp_tau_s). Its noise is the drive pickoff's phase flicker
# (1/f), which the compensation passes on at the bias slope (35 (deg/s)/deg on the
# default part) on top of the quadrature it already leaks into the uncompensated rate
# (26 (deg/s)/deg, 1500 deg/s of quadrature): one stage of 5 s left the output's Allan
# deviation at 10 s 1.84x the uncompensated. Three stages take that noise down as 1/f^4
# above 11 mHz; their ramp lag (45 s) is the gradient term's, fitted with them in place
# (two stages of 25 s left 1.11x at 10 s on the default part's verification run for the
# same ramp residual). The choice is the default part's trade-off between the noise at
# 10 s and a 2 K/min ramp's residual (docs/compensation-noise.md, tools/comp_filter_study).
COMP_TAU_S = 15.0
COMP_STAGES = 3
# The fast path beside it (rate.comp_fast_tau_s): one stage of 5 s, its own gradient term
# fitted on the same run with the slow path's polynomial. Three stages of 15 s lag a fast
# transient by 45 s, which the slow path's gradient term takes back only for a steady rate
# of change: on the default part's cool-down (up to 6 K/min, its rate reversing within a
# minute) the compensated 1 s means had 0.903 deg/s std. The firmware blends the two
# (rate_channel_comp_refresh): the slow path while they agree within rate.comp_blend_dps,
# the fast one beyond twice that.
COMP_FAST_TAU_S = 5.0
# The blend: BLEND_SIGMAS standard deviations of the paths' difference at rest (the 1 s
# means of the plateaus' rest windows), so that the slow path's noise is not traded away at
# rest, within BLEND_MIN_DPS..BLEND_MAX_DPS (half the +-0.2 deg/s the compensation is held
# to: where the blend departs from the fast path, it is by less than that).
BLEND_SIGMAS = 4.0
BLEND_MIN_DPS, BLEND_MAX_DPS = 0.02, 0.1
START_S = 30.0         # the start-up (lock, P's fast start) is left out of every fit
BIN_S = 1.0
# The ramp of the verification (issue: 25 -> 65 degC at 2 K/min), then the part settles.
RAMP_FROM_C, RAMP_TO_C, RAMP_K_PER_MIN = 25.0, 65.0, 2.0
RAMP_LEAD_S, RAMP_TAIL_S = 120.0, 600.0
# 9600 s: the 10 s noise ratio judged on 960 windows, its uncertainty from 8 segments of
# 1200 s (NOISE_10S_MIN_WINDOWS, NOISE_SEGMENT_S; 1200 s left it a scatter of +-0.045)
NOISE_S = 9600.0
# A fast thermal transient (a heat gun, then the room; the shape of the thesis's cool-down,
# other levels and time constants than tools/report's cool-down): from the base the
# surroundings rise towards the hot level with a time constant of tau_heat for heat_s,
# then fall back with tau_cool. On the default part the structure's rate of change jumps
# from 0 to a few K/min at the start and reverses within a minute at the end of the
# heating: what a slow thermometer lags. (base degC, hot degC, lead s, heat s, tau_heat s,
# tau_cool s, total s)
TRANSIENT = (25.0, 65.0, 120.0, 600.0, 90.0, 45.0, 2400.0)
# A cold start (IEEE 1431 12.6, warm-up time): power-on after a long power-off, every node
# of the thermal network at the ambient (plant.cold_start), at rest at a constant ambient;
# the part's own dissipation then warms the circuit and the structure over minutes (the
# default part's slowest thermal mode: 306 s, tools/thermal_warmup.py). (ambient degC,
# run s)
WARMUP = (25.0, 1800.0)
# The uncompensated output's final level: its mean over the run's last this many seconds.
WARMUP_FINAL_S = 60.0
# The raw output's warm-up change is reported from its level this long after power-on (the
# drive locked, P's fast start over).
WARMUP_EARLY_S = 10.0
# The warm-up time is also reported on the output averaged over the preceding this many
# seconds (warmup_time_avg_s). The 1 s figure is the last 1 s mean beyond the bound, and
# a settled part's 1 s means scatter by 0.03..0.05 deg/s sd with the compensation's slow
# wander (the thermometer's 1/f phase flicker at the bias slope) on top: on the default
# part's quick calibration the same cold start read 31..566 s over ten noise seeds of a
# direct gyro-sim run, and 185 s through a UART session (its noise generators thousands of
# seconds old: more of the slow wander). Over 10 s the same runs read 30..83 s, the
# session 86 s: the warm-up transient, not the noise's largest excursion.
WARMUP_AVG_S = 10.0


@dataclasses.dataclass(frozen=True)
class Protocol:
    """The thermal stage's and its verification's profiles."""
    name: str
    cal_plateaus_c: tuple
    dwell_s: float            # per chamber plateau, calibration and verification alike
    verify_plateaus_c: tuple
    ramp: tuple               # (from degC, to degC, K/min, lead s, tail s)
    noise_s: float
    note: str
    span_from_data: bool = False  # the valid thermometer span (thermcal.fitted_span)
    comp_tau_s: float = COMP_TAU_S  # the compensation's thermometer filter it fits with
    comp_stages: int = COMP_STAGES
    comp_fast_tau_s: float = COMP_FAST_TAU_S  # its fast path (0: none)
    transient: tuple = TRANSIENT
    warmup: tuple = WARMUP


FULL = Protocol("full", CAL_PLATEAUS_C, CAL_DWELL_S, VERIFY_PLATEAUS_C,
                (RAMP_FROM_C, RAMP_TO_C, RAMP_K_PER_MIN, RAMP_LEAD_S, RAMP_TAIL_S), NOISE_S,
                "chamber -40..85 degC")
# --quick (lots): the compensation over 15..35 degC only, from three plateaus of one
# structure time constant of the default part (400 s) each: the plateaus are not settled,
# the gradient term takes the transients; the rate is valid only over the thermometer
# span the fit's data reached (rate.p_range_deg: about 19..29 degC of structure on the
# default part), so outside it the part says so instead of guessing. Verified the same
# way on plateaus and a ramp inside the span, at other temperatures.
# Its thermometer filter is one stage of 5 s (the flow's before the three-stage one): on
# plateaus of 400 s the fit is all transients, and with three stages of 15 s the default
# part's quick calibration left -0.39 deg/s at its 20 degC plateau (failed). A quick
# calibration's noise at 10 s is reported, not judged (its 120 s record).
# No fast path (its one 5 s stage is the fast path already); its transient stays inside
# the span it fits (22 -> 29 degC of surroundings).
QUICK = Protocol("quick", (25.0, 15.0, 35.0), 400.0, (20.0, 30.0),
                 (22.0, 28.0, 2.0, 60.0, 120.0), 120.0, "15..35 degC only", True, 5.0, 1,
                 0.0, (22.0, 29.0, 60.0, 300.0, 60.0, 30.0, 1200.0), (25.0, 600.0))
# The transient is held to the ramp's limit: the 1 s means of the bias within 0.2 deg/s
# std (the thesis: 0.462 deg/s over its cool-down, in sample).
LIMITS = {"ramp_bias_std_dps": 0.2, "plateau_bias_dps": 0.2, "sf_ppm": 500.0,
          "noise_ratio": 1.1, "valid_fraction": 0.9, "transient_bias_std_dps": 0.2,
          "warmup_bias_dps": 0.2, "warmup_worst_dps": 1.0}


def _plateau_profiles(temps_c, dwell_s):
    """(ambient steps, rate steps, duration): the rate steps at each plateau's end."""
    amb = [[dwell_s, t] for t in temps_c]
    rate = []
    lead = dwell_s - TAIL_S - 3 * STEP_S
    for _ in temps_c:
        rate += [[lead, 0.0], [STEP_S, STEP_RATE_DPS], [STEP_S, -STEP_RATE_DPS],
                 [STEP_S, STEP_RATE_DPS], [TAIL_S, 0.0]]
    return amb, rate, dwell_s * len(temps_c)


def plateau_scenario(temps_c, dwell_s, doc):
    amb, rate, dur = _plateau_profiles(temps_c, dwell_s)
    return dict(doc, duration_s=dur, csv_rate_hz=10,
                ambient_c={"kind": "steps", "edge_s": CHAMBER_EDGE_S, "steps": amb},
                rate_dps={"kind": "steps", "edge_s": TABLE_EDGE_S, "steps": rate})


def ramp_scenario(doc, proto=FULL):
    t_from, t_to, k_per_min, lead, tail = proto.ramp
    dur_ramp = (t_to - t_from) / k_per_min * 60.0
    return dict(doc, duration_s=lead + dur_ramp + tail, csv_rate_hz=10,
                ambient_c={"kind": "ramp", "value": t_from, "slope_per_s": k_per_min / 60.0,
                           "t_start_s": lead, "t_end_s": lead + dur_ramp})


def transient_scenario(doc, proto=FULL):
    base, hot, lead, heat, tau_h, tau_c, total = proto.transient
    return dict(doc, duration_s=total, csv_rate_hz=10,
                ambient_c={"kind": "heat_cool", "value": base, "hot_value": hot,
                           "t_start_s": lead, "heat_s": heat, "tau_heat_s": tau_h,
                           "tau_cool_s": tau_c})


def warmup_scenario(doc, proto=FULL):
    ambient_c, total = proto.warmup
    return dict(doc, duration_s=total, csv_rate_hz=10, plant={"cold_start": True},
                ambient_c={"kind": "const", "value": ambient_c})


def noise_scenario(doc, proto=FULL):
    return dict(doc, duration_s=proto.noise_s + START_S, csv_rate_hz=100)


def rest_avg_s(dwell_s):
    """The rest window judged before a plateau's rate steps: REST_AVG_S, or half of what a
    short plateau leaves before them."""
    return min(REST_AVG_S, 0.5 * (dwell_s - TAIL_S - 3 * STEP_S))


def _window(t, t0, t1):
    return (t >= t0) & (t < t1)


def plateau_windows(t, k, dwell_s):
    """Index masks of plateau k: (rest, first +R, -R, second +R), at their steps' ends."""
    end = (k + 1) * dwell_s
    t_pos2_end = end - TAIL_S
    t_neg_end = t_pos2_end - STEP_S
    t_pos_end = t_neg_end - STEP_S
    t_rest_end = t_pos_end - STEP_S - TABLE_EDGE_S
    return (_window(t, t_rest_end - rest_avg_s(dwell_s), t_rest_end),
            _window(t, t_pos_end - STEP_AVG_S, t_pos_end),
            _window(t, t_neg_end - STEP_AVG_S, t_neg_end),
            _window(t, t_pos2_end - STEP_AVG_S, t_pos2_end))


def plateau_points(log, n, dwell_s, out="rate_unc_dps"):
    """Per plateau: mean P_f, output at rest, gain (u(+R) - u(-R)) / 2R, valid fraction."""
    t = log["t_s"]
    rows = []
    for k in range(n):
        rest, pos, neg, pos2 = plateau_windows(t, k, dwell_s)
        u = log[out]
        u_pos = 0.5 * (np.mean(u[pos]) + np.mean(u[pos2]))
        pf = log["p_f_deg"]
        p_pos = 0.5 * (np.mean(pf[pos]) + np.mean(pf[pos2]))
        rows.append({"p_deg": float(np.mean(pf[rest])),
                     "p_turn_deg_per_dps": float((p_pos - np.mean(pf[neg]))
                                                 / (2 * STEP_RATE_DPS)),
                     "t_struct_c": (float(np.mean(log["t_struct_c"][rest]))
                                    if "t_struct_c" in log else float("nan")),
                     "bias_dps": float(np.mean(u[rest])),
                     "gain": float((u_pos - np.mean(u[neg])) / (2 * STEP_RATE_DPS)),
                     "valid": float(np.mean(log["rate_valid"][rest | pos | neg | pos2]))})
    return rows


def gradient_hp(t_s, p_deg, tau_s, t0_s=START_S):
    """P_f - LP_tau(P_f) as the firmware forms it (rate_channel_update_p), on a log's P_f:
    per firmware update the high-pass keeps 1 - a of (its value + P_f's step); the log's
    rows are coarser (evenly spaced), a row's keep the product of its updates',
    exp(-dt / tau). Zero before t0_s, as the firmware's is until P_f has settled."""
    t = np.asarray(t_s, dtype=float)
    step = np.diff(np.asarray(p_deg, dtype=float), prepend=float(p_deg[0]))
    step[t < t0_s] = 0.0
    keep = float(np.exp(-float(np.median(np.diff(t))) / tau_s))
    return lfilter([keep], [1.0, -keep], step)


def comp_thermometer(t_s, p_deg, tau_s=COMP_TAU_S, stages=COMP_STAGES, t0_s=START_S):
    """P_c, the compensation's thermometer: P_f through `stages` first-order low-passes of
    tau_s each as the firmware does (rate.comp_tau_s, rate.comp_stages; tau 0: P_f
    itself). The filters start at P_f at t0_s (the firmware's start once P_f has
    settled, comp_filters.h), not at the log's first row (P_f 0 before its first
    update): P_c is P_f's value at t0_s before it."""
    t = np.asarray(t_s, dtype=float)
    p = np.asarray(p_deg, dtype=float)
    if tau_s <= 0.0:
        return p
    i0 = min(int(np.searchsorted(t, t0_s)), p.size - 1)
    p = np.where(np.arange(p.size) < i0, p[i0], p)
    keep = float(np.exp(-float(np.median(np.diff(t))) / tau_s))
    for _ in range(stages):
        p = p[0] + lfilter([1.0 - keep], [1.0, -keep], p - p[0])
    return p


def _lstsq(cols, y):
    a = np.column_stack(cols)
    c, *_ = np.linalg.lstsq(a, y, rcond=None)
    return c, y - a @ c


def fitted_span(log, pts, span_from_data, comp_tau_s=COMP_TAU_S, comp_stages=COMP_STAGES):
    """(reference, half span) of the thermometer the fit covers: the plateaus' P, or with
    span_from_data the extremes of the 1 s means of P_c at rest that the bias fit uses
    (short plateaus do not reach their ambient; the transitions between them do reach
    further, and the fit had them)."""
    p = np.array([r["p_deg"] for r in pts])
    if span_from_data:
        t = log["t_s"]
        rest = (np.abs(log["rate_true_dps"]) < 1e-9) & (t >= START_S)
        p_c = comp_thermometer(t, log["p_f_deg"], comp_tau_s, comp_stages)
        p = tempcomp.bin_average(t[rest], {"p": p_c[rest]}, BIN_S)["p"]
    return 0.5 * (p.min() + p.max()), 0.5 * (p.max() - p.min())


def fast_path(log, y, rest, slow, comp_fast_tau_s, ref, dwell_s, n_plateaus):
    """The fast path's gradient term (rate.grad_fast_dps_per_deg) on the same rest bins as
    the slow fit, with the slow path's polynomial (slow: its "c", "tau", "x", "h"; y the
    output times the slow path's SF, as the firmware forms it), and the blend:
    BLEND_SIGMAS standard deviations of the two paths' difference over the plateaus' rest
    windows (1 s means, the most settled part of the run), within BLEND_MIN_DPS..
    BLEND_MAX_DPS. Returns (values, figures)."""
    t = log["t_s"]
    c = slow["c"]
    p_f = comp_thermometer(t, log["p_f_deg"], comp_fast_tau_s, 1)
    h_f = gradient_hp(t, p_f, slow["tau"])
    b_f = tempcomp.poly_eval(c[:4], p_f - ref)
    b = tempcomp.bin_average(t[rest], {"r": (y - b_f)[rest], "h": h_f[rest]}, BIN_S)
    k_f, resid = _lstsq([b["h"]], b["r"])
    k_f = float(k_f[0])
    d = (b_f + k_f * h_f) - (tempcomp.poly_eval(c[:4], slow["x"]) + float(c[4]) * slow["h"])
    win = np.zeros(t.size, dtype=bool)
    for k in range(n_plateaus):
        win |= plateau_windows(t, k, dwell_s)[0]
    win &= rest
    sd = float(np.std(tempcomp.bin_average(t[win], {"d": d[win]}, BIN_S)["d"]))
    blend = float(np.clip(BLEND_SIGMAS * sd, BLEND_MIN_DPS, BLEND_MAX_DPS))
    return ({"rate.comp_fast_tau_s": float(comp_fast_tau_s),
             "rate.grad_fast_dps_per_deg": k_f, "rate.comp_blend_dps": blend},
            {"grad_fast_dps_per_deg": k_f,
             "fast_fit_rms_1s_dps": float(np.sqrt(np.mean(resid ** 2))),
             "paths_difference_sd_dps": sd, "blend_dps": blend})


def fit(log, temps_c, dwell_s, span_from_data=False, comp_tau_s=COMP_TAU_S,
        comp_stages=COMP_STAGES, tau_grid_s=TAU_GRID_S, comp_fast_tau_s=0.0):
    """The compensation from the calibration run: a dict of firmware values and figures.
    The thermometer P_c is the firmware's for (comp_tau_s, comp_stages); the gradient
    term's time constant the best of tau_grid_s; with comp_fast_tau_s > 0 the fast path
    and its blend (fast_path)."""
    n_plateaus = len(temps_c)
    pts = plateau_points(log, n_plateaus, dwell_s)
    p = np.array([r["p_deg"] for r in pts])
    ref, half = fitted_span(log, pts, span_from_data, comp_tau_s, comp_stages)
    x_pl = p - ref
    inv_gain = 1.0 / np.array([r["gain"] for r in pts])
    s = tempcomp.poly_fit(x_pl, inv_gain, min(SF_ORDER, n_plateaus - 2))
    s0 = s[0]
    sf_c = tempcomp.padded(s / s0, SF_ORDER + 1)
    t = log["t_s"]
    rest = (np.abs(log["rate_true_dps"]) < 1e-9) & (t >= START_S)
    p_c = comp_thermometer(t, log["p_f_deg"], comp_tau_s, comp_stages)
    best = None
    for tau in tau_grid_s:
        h = gradient_hp(t, p_c, tau)
        x = p_c - ref
        y = log["rate_unc_dps"] * tempcomp.poly_eval(s, x)
        b = tempcomp.bin_average(t[rest], {"x": x[rest], "y": y[rest], "h": h[rest]}, BIN_S)
        c, r = _lstsq([np.ones_like(b["x"]), b["x"], b["x"] ** 2, b["x"] ** 3, b["h"]], b["y"])
        rms = float(np.sqrt(np.mean(r ** 2)))
        if best is None or rms < best["rms"]:
            best = {"tau": tau, "c": c, "rms": rms, "x": x, "h": h, "y": y}
    c = best["c"]
    # The bias in the units of the rescaled output (u s0 -> the SF(x)/s0 of the firmware):
    # rate = u s0 (SF/s0) - B - k h, the same B and k.
    bias_pl = np.array([r["bias_dps"] for r in pts]) * tempcomp.poly_eval(s, x_pl)
    resid_pl = bias_pl - tempcomp.poly_eval(c[:4], x_pl)
    # What is left of the rate's turn of P at each plateau (the firmware took out
    # rate.p_rate_deg_per_dps, measured at room temperature): a line in x, its constant
    # for the caller to add to that value.
    turn = np.array([r["p_turn_deg_per_dps"] for r in pts])
    turn_c1, turn_c0 = (float(v) for v in np.polyfit(x_pl, turn, 1))
    values = dict(zip(tempcomp.BIAS_PARAMS, (float(x) for x in c[:4])))
    values["rate.p_rate_c1_per_dps"] = turn_c1
    # P's span over the chamber's (what a bench knows): a structure that did not reach
    # the chamber's extremes (short plateaus) makes the slope smaller, the limit tighter.
    # (Not a line through the plateaus' P: short ones are read while P still moves.)
    p_per_k = 2.0 * half / (max(temps_c) - min(temps_c))
    values["rate.p_slew_max_deg_s"] = max(p_per_k * SLEW_MAX_K_PER_S, SLEW_MIN_DEG_S)
    values.update({"cal.ref_p_deg": float(ref),
                   "rate.p_range_deg": float(half * (1 + 2 * P_RANGE_MARGIN)),
                   "rate.sf_c1_per_deg": float(sf_c[1]), "rate.sf_c2_per_deg2": float(sf_c[2]),
                   "rate.sf_c3_per_deg3": float(sf_c[3]), "rate.sf_c4_per_deg4": float(sf_c[4]),
                   "rate.bias_grad_dps_per_deg": float(c[4]),
                   "rate.grad_tau_s": float(best["tau"]),
                   "rate.comp_tau_s": float(comp_tau_s), "rate.comp_stages": int(comp_stages)})
    figures = {"plateaus_c": list(temps_c), "dwell_s": dwell_s,
               "p_deg": p.tolist(), "p_span_deg": float(2 * half),
               "raw_bias_dps": [r["bias_dps"] for r in pts],
               "raw_gain": [r["gain"] for r in pts], "scale_factor_s0": float(s0),
               "plateau_residual_dps": resid_pl.tolist(),
               "fit_rms_1s_dps": best["rms"], "grad_tau_s": best["tau"],
               "p_turn_residual_deg_per_dps": turn.tolist(), "p_turn_c0_deg_per_dps": turn_c0,
               "p_turn_c1_per_dps": turn_c1, "p_per_k_deg": p_per_k}
    if comp_fast_tau_s > 0.0:
        fv, ff = fast_path(log, best["y"], rest, best, comp_fast_tau_s, ref, dwell_s,
                           n_plateaus)
        values.update(fv)
        figures.update(ff)
    return values, s0, figures


def rest_bins(log, t0, t1, columns):
    """1 s means of the named columns at rest between t0 and t1, valid samples only:
    (dict column -> means, with "t_s"; the valid fraction of the window). The bins of the
    ramp's judgement, so that a report's bias against temperature is the judged one."""
    t = log["t_s"]
    m = _window(t, t0, t1) & (np.abs(log["rate_true_dps"]) < 1e-9) & (log["rate_valid"] > 0.5)
    valid = float(np.mean(log["rate_valid"][_window(t, t0, t1)] > 0.5))
    if not np.any(m):
        return {c: np.zeros(0) for c in ("t_s",) + tuple(columns)}, valid
    return tempcomp.bin_average(t[m], {c: log[c][m] for c in columns}, BIN_S), valid


def bias_means(log, t0, t1, out="rate_dps"):
    """1 s means of the output at rest between t0 and t1, valid samples only."""
    bins, valid = rest_bins(log, t0, t1, (out,))
    return bins[out], valid


def verify_plateaus(log, temps_c, dwell_s):
    pts = plateau_points(log, len(temps_c), dwell_s, out="rate_dps")
    rows = []
    for tc, r in zip(temps_c, pts):
        sf_ppm = (r["gain"] - 1.0) * 1e6
        rows.append({"ambient_c": tc, "t_struct_c": r["t_struct_c"], "p_deg": r["p_deg"],
                     "bias_dps": r["bias_dps"], "sf_ppm": sf_ppm, "valid": r["valid"],
                     "ok": bool(abs(r["bias_dps"]) <= LIMITS["plateau_bias_dps"] and
                                abs(sf_ppm) <= LIMITS["sf_ppm"] and
                                r["valid"] >= LIMITS["valid_fraction"])})
    return rows


def verify_ramp(log, proto=FULL):
    t_from, t_to, k_per_min, lead, _ = proto.ramp
    t_end = log["t_s"][-1]
    means, valid = bias_means(log, lead, t_end)
    std = float(np.std(means)) if means.size else float("nan")
    return {"from_c": t_from, "to_c": t_to, "k_per_min": k_per_min,
            "bias_1s_std_dps": std,
            "bias_1s_max_abs_dps": float(np.max(np.abs(means))) if means.size else float("nan"),
            "valid_fraction": valid,
            "ok": bool(np.isfinite(std) and std <= LIMITS["ramp_bias_std_dps"] and
                       valid >= LIMITS["valid_fraction"])}


def verify_transient(log, proto=FULL):
    """The fast transient (transient_scenario): the 1 s means of the bias at rest after the
    lead, valid samples only, their std within LIMITS["transient_bias_std_dps"]."""
    base, hot, lead, heat, tau_h, tau_c, _ = proto.transient
    means, valid = bias_means(log, lead, log["t_s"][-1])
    std = float(np.std(means)) if means.size else float("nan")
    return {"base_c": base, "hot_c": hot, "heat_s": heat, "tau_heat_s": tau_h,
            "tau_cool_s": tau_c, "bias_1s_std_dps": std,
            "bias_1s_pp_dps": float(np.ptp(means)) if means.size else float("nan"),
            "bias_1s_max_abs_dps": float(np.max(np.abs(means))) if means.size else float("nan"),
            "valid_fraction": valid,
            "ok": bool(np.isfinite(std) and std <= LIMITS["transient_bias_std_dps"] and
                       valid >= LIMITS["valid_fraction"])}


def settled_time(t, ok):
    """The time of the first sample after which ok holds to the end of t; None when the
    last sample does not hold."""
    if t.size == 0 or not ok[-1]:
        return None
    bad = np.flatnonzero(~ok)
    return float(t[0 if bad.size == 0 else bad[-1] + 1])


def _bins_from_zero(log, mask, column):
    """Means of `column` over the samples in mask, in BIN_S bins from power-on: (bin
    starts, means; NaN where a bin has none)."""
    t = log["t_s"]
    k = np.floor(t / BIN_S).astype(np.int64)
    n = int(k[-1]) + 1
    cnt = np.bincount(k[mask], minlength=n)
    tot = np.bincount(k[mask], weights=log[column][mask], minlength=n)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.arange(n) * BIN_S, np.where(cnt > 0, tot / np.maximum(cnt, 1), np.nan)


def warmup_means(log):
    """A cold start's 1 s means from power-on, at rest: "t_s" (bin starts), "rate_dps" (its
    valid samples; NaN where a bin has none), "rate_unc_dps" (every sample)."""
    rest = np.abs(log["rate_true_dps"]) < 1e-9
    t_bin, comp = _bins_from_zero(log, rest & (log["rate_valid"] > 0.5), "rate_dps")
    return {"t_s": t_bin, "rate_dps": comp,
            "rate_unc_dps": _bins_from_zero(log, rest, "rate_unc_dps")[1]}


def trailing_means(values, n):
    """The mean of the finite values among each entry and the n - 1 before it (fewer at
    the start); NaN where there are none."""
    ok = np.isfinite(values)
    tot = np.concatenate([[0.0], np.cumsum(np.where(ok, values, 0.0))])
    cnt = np.concatenate([[0], np.cumsum(ok)])
    k = np.arange(values.size)
    lo = np.maximum(k - n + 1, 0)
    c = cnt[k + 1] - cnt[lo]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(c > 0, (tot[k + 1] - tot[lo]) / np.maximum(c, 1), np.nan)


def warmup_time_avg(t_bin, comp, bound):
    """The time from power-on after which the valid output's mean over the preceding
    WARMUP_AVG_S (its 1 s means; since power-on in the first seconds) lies within bound
    of the input: the end of the first such window; None when the last one is not."""
    m = trailing_means(comp, int(round(WARMUP_AVG_S / BIN_S)))
    t = settled_time(t_bin, np.isfinite(m) & (np.abs(m) <= bound))
    return None if t is None else t + BIN_S


def verify_warmup(log, proto=FULL):
    """A cold start at rest (warmup_scenario), IEEE 1431 12.6: the warm-up time is the
    start of the first 1 s bin from power-on after which every bin's mean of the valid
    output lies within LIMITS["warmup_bias_dps"] of the input (0: a bin with no valid
    sample is not warm); the raw output's own settling (within the same bound of its
    final level, the mean of its last WARMUP_FINAL_S; None when it still moves at the end
    of the run) says what the compensation saves. warmup_time_avg_s: the same on the
    output averaged over WARMUP_AVG_S (warmup_time_avg), which a late 1 s excursion of the
    noise does not move.
    Judged: the output ends warm, is valid for LIMITS["valid_fraction"] of the run after
    its first valid sample, and no valid 1 s mean is off by more than
    LIMITS["warmup_worst_dps"] (a wrong rate the product would stand behind)."""
    ambient_c, total = proto.warmup
    t, bound = log["t_s"], LIMITS["warmup_bias_dps"]
    if t.size < 2 or t[-1] < 2.0 * WARMUP_FINAL_S:
        raise InputError(f"{log.path}: {t[-1] if t.size else 0:.3g} s from power-on: too short "
                         f"for a warm-up time (at least {2.0 * WARMUP_FINAL_S:g} s)")
    valid = log["rate_valid"] > 0.5
    m = warmup_means(log)
    t_bin, comp, unc = m["t_s"], m["rate_dps"], m["rate_unc_dps"]
    end = t_bin[-1] + BIN_S
    final = float(np.nanmean(unc[t_bin >= end - WARMUP_FINAL_S]))
    before = float(np.nanmean(unc[(t_bin >= end - 2 * WARMUP_FINAL_S) &
                                  (t_bin < end - WARMUP_FINAL_S)]))
    warm = np.isfinite(comp) & (np.abs(comp) <= bound)
    t_warm = settled_time(t_bin, warm)
    # Still moving at the end (its last minute against the one before by more than a
    # quarter of the bound): the run is shorter than the raw output's warm-up.
    raw_settled = abs(final - before) <= 0.25 * bound
    t_raw = settled_time(t_bin, np.abs(unc - final) <= bound) if raw_settled else None
    first = np.flatnonzero(valid)
    after = t >= t[first[0]] if first.size else np.zeros_like(valid)
    frac = float(np.mean(valid[after])) if np.any(after) else 0.0
    worst = float(np.nanmax(np.abs(comp))) if np.any(np.isfinite(comp)) else float("nan")
    return {"ambient_c": ambient_c, "run_s": float(t[-1]), "bound_dps": bound,
            "warmup_time_s": t_warm, "raw_settle_time_s": t_raw,
            "warmup_avg_s": WARMUP_AVG_S,
            "warmup_time_avg_s": warmup_time_avg(t_bin, comp, bound),
            "raw_final_dps": final, "raw_end_drift_dps_per_min": (final - before) * 60.0
            / WARMUP_FINAL_S, "raw_settled_in_run": bool(raw_settled),
            "raw_change_dps": float(final - unc[int(WARMUP_EARLY_S / BIN_S)]),
            "worst_valid_1s_dps": worst, "valid_fraction": frac,
            "t_struct_c": ([float(log["t_struct_c"][0]), float(log["t_struct_c"][-1])]
                           if "t_struct_c" in log else None),
            "ok": bool(t_warm is not None and frac >= LIMITS["valid_fraction"] and
                       np.isfinite(worst) and worst <= LIMITS["warmup_worst_dps"])}


# The noise ratio is judged at 1 s and, on a record of at least this many times 10 s, at
# 10 s as well; a shorter record (--quick's 120 s) reports the 10 s ratio without judging
# it. The 10 s ratio scatters from one noise realisation to the next by about as much as
# each deviation does, not less: the compensation's added noise (P's phase flicker through
# the bias slope) and the uncompensated output's noise are nearly independent at 10 s, so
# the ratio's square is 1 + (added / uncompensated)^2 plus twice their correlation over the
# record's windows, and that correlation scatters by about 1 / sqrt(windows). Measured on
# the flow's 1200 s run over seeds 2001..2012 (docs/compensation-noise.md, "How far the
# 10 s figure can be trusted"): 1.049 +- 0.043 on the quad -800 part, 1.060 +- 0.048 on
# the default part (sd), 2 and 3 of 12 seeds above 1.1 on parts whose mean is within it.
# Hence NOISE_S (960 windows), and the ratio's uncertainty reported with it: the ratios of
# consecutive NOISE_SEGMENT_S segments (batch means), their standard deviation / sqrt(n).
NOISE_10S_MIN_WINDOWS = 60
NOISE_SEGMENT_S = 1200.0


def _ratio_10s_segments(t, comp, unc, fs):
    """The 10 s ratio of each consecutive NOISE_SEGMENT_S segment of a record (allantools
    oadev at exactly 10 s, rate as frequency data)."""
    n = int(round(NOISE_SEGMENT_S * fs))
    out = []
    for k in range(t.size // n):
        s = slice(k * n, (k + 1) * n)
        ad = [allantools.oadev(x[s], rate=fs, data_type="freq", taus=[10.0])[1][0]
              for x in (comp, unc)]
        out.append(float(ad[0] / ad[1]))
    return out


def verify_noise(log, proto=FULL):
    """The output noise with the compensation against without it: Allan deviation of
    rate_dps and rate_unc_dps of the same run at 25 degC (after START_S), at 1 s and 10 s;
    each ratio within LIMITS["noise_ratio"] (10 s only judged on a long enough record).
    The 10 s ratio's standard uncertainty and CI_LEVEL interval (Student's t) come from the
    ratios of the record's NOISE_SEGMENT_S segments (reported, not judged: the judged
    figure is the whole record's)."""
    t = log["t_s"]
    m = t >= START_S
    fs = 1.0 / float(np.median(np.diff(t)))
    comp = allan.adev_curve(log["rate_dps"][m], fs)
    unc = allan.adev_curve(log["rate_unc_dps"][m], fs)

    def at(curve, tau):
        return float(np.interp(tau, curve.tau_s, curve.adev_dph))

    a_c, a_u = at(comp, 1.0), at(unc, 1.0)
    a_c10, a_u10 = at(comp, 10.0), at(unc, 10.0)
    record_s = float(t[m][-1] - t[m][0])
    judge_10s = record_s >= NOISE_10S_MIN_WINDOWS * 10.0
    ok_1s = a_c / a_u <= LIMITS["noise_ratio"]
    ok_10s = a_c10 / a_u10 <= LIMITS["noise_ratio"]
    segs = _ratio_10s_segments(t[m], log["rate_dps"][m], log["rate_unc_dps"][m], fs)
    if len(segs) >= 2:
        u10 = float(np.std(segs, ddof=1) / np.sqrt(len(segs)))
        ci10 = ([float(v) for v in stats.t.interval(allan.CI_LEVEL, len(segs) - 1,
                                                    loc=a_c10 / a_u10, scale=u10)]
                if u10 > 0 else [a_c10 / a_u10] * 2)
    else:
        u10, ci10 = None, None
    return {"adev_1s_compensated_dph": a_c, "adev_1s_uncompensated_dph": a_u,
            "ratio": a_c / a_u, "ok": bool(ok_1s and (ok_10s or not judge_10s)),
            "adev_10s_compensated_dph": a_c10, "adev_10s_uncompensated_dph": a_u10,
            "ratio_10s": a_c10 / a_u10, "ratio_10s_judged": bool(judge_10s),
            "ratio_10s_segments": segs, "ratio_10s_u": u10, "ratio_10s_ci": ci10,
            "record_s": record_s,
            "how": "overlapping Allan deviation (allantools.oadev, rate as frequency data) of "
                   f"rate_dps and rate_unc_dps of the same {proto.noise_s:g} s run at 25 degC "
                   f"(the first {START_S:g} s left out), csv at {fs:g} Hz, read at 1 s "
                   "(judged) and 10 s (" + ("judged" if judge_10s else
                                            f"reported: a record under "
                                            f"{NOISE_10S_MIN_WINDOWS * 10:g} s") + "); the "
                   f"10 s ratio's uncertainty from its {NOISE_SEGMENT_S:g} s segments "
                   f"(batch means, {100 * allan.CI_LEVEL:.1f} % Student t interval)"}
