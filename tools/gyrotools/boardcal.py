"""The board thermometer's model of the bias (firmware/gyro/board_therm.h), fitted by the
calibration flow (tools/calibrate --board-temp) on its chamber run.

The firmware fuses the compensation in P with a model of the bias read from the board
sensor (board.fuse 1):

    y = H(s) b,  H = (1 + s tz1)(1 + s tz2) / ((1 + s tp1)(1 + s tp2))
    M = c0 + c1 (y - ref) + c2 (y - ref)^2 + c3 (y - ref)^3
    B = B_s - LP_T(B_s - sf M)       (weighed in by w after power-on)

b the sensor's reading (the log's board_c, as the firmware took it), B_s and sf the
compensation's static bias and scale factor in P, T the crossover (board.crossover_s). In a network of
lumped thermal nodes driven by the surroundings alone every node is the board's
temperature through two zeros over two poles, and the bias a static law of the nodes: H
and the cubic are fitted by least squares on the 1 s means of the chamber run at rest
(scipy least_squares on the logarithms of the four time constants, the cubic by linear
least squares inside), the target the linearised output u at rest, the bias as the
pickoff delivers it (the firmware scales M by the compensation's scale factor). H runs here exactly as the
firmware runs it: in its lag form, one step every BOARD_STEP_S on the reading held.

The model knows one heat input; the board's own warm-up after a power-on is another, so
the firmware hands over to the fusion board.start_s after power-on (when H's step
response has settled within SETTLE_REL for good: the time the model takes to forget a
disagreement it started with; a pole its zero nearly cancels does not count) over
board.fade_s.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy import optimize
from scipy.signal import lfilter

from . import tempcomp, thermcal
from .errors import InputError

BOARD_STEP_S = 0.1        # firmware/gyro/board_therm.h BOARD_THERM_STEP_S
TC_MIN_S, TC_MAX_S = 1.0, 20000.0   # the parameters' range (board.tz1_s ...)
GUESS_S = (300.0, 30.0, 600.0, 60.0)
# The crossover: P's flicker is in excess from 10 s on (docs/compensation-noise.md), and
# above the crossover the fused bias passes T times the rate of change of P's
# disagreement with the model (a complementary filter's lag): measured offline on the flow's
# logs, the loose part's transient 0.279 / 0.197 / 0.118 / 0.082 deg/s std at T = 3 / 2 /
# 1 / 0.5 s, the default part's noise at 1 s 1.002 / 1.004 / 1.011 / 1.023 times the
# uncompensated (the sensor's steps). 1 s.
CROSSOVER_S = 1.0
SETTLE_REL = 0.01          # the hand-over after power-on: H's step response settled to this
START_MIN_S = 300.0
FADE_S = 300.0
SPAN_MARGIN = 0.05        # of the fitted span of y, each side (as rate.p_range_deg's)
SPAN_MARGIN_MIN_C = 1.0
MIN_READINGS = 60         # a minute of the sensor at least
MIN_SPAN_C = 5.0          # the board must have moved for a model to be fitted
AGREE_FACTOR = 3.0        # board.agree_dps: this times the most P and the model part by
AGREE_MIN_DPS = 1.0


@dataclasses.dataclass
class BoardModel:
    tz_s: tuple
    tp_s: tuple
    ref_c: float
    c: np.ndarray
    y_min_c: float
    y_max_c: float
    rms_dps: float        # the fit's residual on its 1 s means


def held_grid(t_s, board_c):
    """The reading held on the firmware's step grid (BOARD_STEP_S from the first reading):
    (t, b). The log's rows may be of any rate; the firmware's steps see the reading the
    row before them holds."""
    t = np.asarray(t_s, dtype=float)
    b = np.asarray(board_c, dtype=float)
    ok = np.isfinite(b)
    if np.count_nonzero(ok) < 2:
        raise InputError("board sensor: no readings in the log (column board_c)")
    t0 = t[np.argmax(ok)]
    grid = np.arange(t0, t[-1] + 1e-9, BOARD_STEP_S)
    k = np.searchsorted(t, grid, side="right") - 1
    return grid, b[np.maximum(k, 0)]


def lead_lag(b, tz_s, tp_s, ref_c):
    """H on the held reading, as board_therm.c runs it: each section in its lag form
    e = (1 - a)(e + step of its input), output in - (1 - r) e; starts in its steady state."""
    y = np.asarray(b, dtype=float) - ref_c
    for tz, tp in zip(tz_s, tp_s):
        a = 1.0 - np.exp(-BOARD_STEP_S / tp)
        r = tz / tp
        # e_k = (1 - a)(e_{k-1} + dx_k): a first-order recursion
        dx = np.diff(y, prepend=y[0])
        e = lfilter([1.0 - a], [1.0, -(1.0 - a)], dx)
        y = y - (1.0 - r) * e
    return y + ref_c


def model_bias(model, b):
    """M on the held reading b (deg/s)."""
    y = lead_lag(b, model.tz_s, model.tp_s, model.ref_c)
    return tempcomp.poly_eval(model.c, y - model.ref_c)


def _bins(t, cols):
    return tempcomp.bin_average(t, cols, thermcal.BIN_S)


def fit(t_s, board_c, bias_dps, rest, start_s=thermcal.START_S):
    """The model of bias_dps (the bias at each row, used where rest) read from board_c:
    BoardModel. InputError when the log cannot carry one (too few readings, a board that
    did not move)."""
    grid, b = held_grid(t_s, board_c)
    if grid.size < MIN_READINGS / BOARD_STEP_S:
        raise InputError(f"board sensor: {grid.size * BOARD_STEP_S:.0f} s of readings; "
                         f"need {MIN_READINGS} s")
    t = np.asarray(t_s, dtype=float)
    bias = np.asarray(bias_dps, dtype=float)
    if not np.all(np.isfinite(bias)):
        bad = int(np.count_nonzero(~np.isfinite(bias)))
        raise InputError(f"board sensor: the bias to model is not finite (nan or inf) at {bad} "
                         "rows")
    if np.any(np.isinf(board_c)):
        raise InputError("board sensor: a reading is inf")
    target = np.interp(grid, t, bias)
    at_rest = np.interp(grid, t, np.asarray(rest, dtype=float)) > 0.999
    bins = _bins(grid, {"b": b, "m": target, "r": at_rest.astype(float)})
    use = (bins["r"] > 0.999) & (bins["t_s"] >= start_s)
    if np.count_nonzero(use) < 20:
        raise InputError("board sensor: fewer than 20 s at rest to fit the model on")
    span = float(np.ptp(bins["b"][use]))
    if span < MIN_SPAN_C:
        raise InputError(f"board sensor: the board moved {span:.2f} degC over the run; a "
                         f"model of the bias needs {MIN_SPAN_C} at least")
    ref = float(np.mean(bins["b"][use]))

    def cubic(tc):
        # the lead-lag on the step grid, compared on its 1 s means
        u = _bins(grid, {"y": lead_lag(b, tc[:2], tc[2:], ref)})["y"][use] - ref
        a = np.column_stack([np.ones_like(u), u, u * u, u ** 3])
        c, *_ = np.linalg.lstsq(a, bins["m"][use], rcond=None)
        return c, bins["m"][use] - a @ c, u

    res = optimize.least_squares(lambda q: cubic(np.exp(q))[1], np.log(GUESS_S),
                                 bounds=(np.log(TC_MIN_S), np.log(TC_MAX_S)))
    tc = tuple(float(v) for v in np.exp(res.x))
    c, r, u = cubic(tc)
    return BoardModel(tc[:2], tc[2:], ref, c, float(u.min() + ref), float(u.max() + ref),
                      float(np.sqrt(np.mean(r ** 2))))


def parting_dps(t_s, board_c, bias_s_dps, model, sf, start_s=thermcal.START_S):
    """The most the compensation's static bias in P (bias_s_dps, at each row) and the
    model (times the scale factor sf at each row) part by on a run: the largest |1 s
    mean of B_s - sf M| after start_s (deg/s)."""
    grid, b = held_grid(t_s, board_c)
    t = np.asarray(t_s, float)
    d = np.interp(grid, t, np.asarray(bias_s_dps, float)) - \
        np.interp(grid, t, np.asarray(sf, float)) * model_bias(model, b)
    bins = _bins(grid, {"d": d})
    keep = bins["t_s"] >= start_s
    return float(np.max(np.abs(bins["d"][keep]))) if np.any(keep) else 0.0


def settle_s(model, rel=SETTLE_REL):
    """When H's unit step response stays within rel of 1 for good (s)."""
    n = int(min(20.0 * max(model.tp_s), 2e5) / BOARD_STEP_S)
    step = np.ones(n)
    step[0] = 0.0
    err = np.abs(lead_lag(step, model.tz_s, model.tp_s, 0.0) - 1.0)
    out = np.flatnonzero(err > rel)
    return float((out[-1] + 1) * BOARD_STEP_S) if out.size else 0.0


def values(model, parting=0.0, crossover_s=CROSSOVER_S, fade_s=FADE_S):
    """The firmware's board.* values of a model (the fusion on); parting the most the bias
    in P and the model parted by on the calibration (parting_dps)."""
    span = model.y_max_c - model.y_min_c
    margin = max(SPAN_MARGIN * span, SPAN_MARGIN_MIN_C)
    start = max(settle_s(model), START_MIN_S)
    return {"board.fuse": 1,
            "board.tz1_s": model.tz_s[0], "board.tz2_s": model.tz_s[1],
            "board.tp1_s": model.tp_s[0], "board.tp2_s": model.tp_s[1],
            "board.ref_c": model.ref_c,
            "board.c0_dps": float(model.c[0]), "board.c1_dps_per_c": float(model.c[1]),
            "board.c2_dps_per_c2": float(model.c[2]), "board.c3_dps_per_c3": float(model.c[3]),
            "board.min_c": model.y_min_c - margin, "board.max_c": model.y_max_c + margin,
            "board.crossover_s": crossover_s, "board.start_s": float(min(start, 1e5)),
            "board.fade_s": fade_s,
            "board.agree_dps": max(AGREE_FACTOR * parting, AGREE_MIN_DPS)}


def doc(model):
    """The model as the report records it."""
    return {"tz_s": list(model.tz_s), "tp_s": list(model.tp_s), "ref_c": model.ref_c,
            "c": [float(v) for v in model.c], "y_span_c": [model.y_min_c, model.y_max_c],
            "fit_rms_1s_dps": model.rms_dps}
