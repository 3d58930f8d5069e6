"""Linearity: the rate output's polynomial linearisation and its sub-range slopes.

The sense pickoff's gain falls with the square of the whole sense amplitude (quadrature,
raw bias and rate together: a capacitive pickoff, a stiffening suspension), so the
uncompensated rate u is a polynomial in the true rate r. The firmware outputs

    L(u) = u + c2 u^2 + c3 u^3          (rate.lin_c2_per_dps, rate.lin_c3_per_dps2)

before the temperature compensation (rate_channel.h). The flow fits it on a rate table
over the full scale, CW and CCW (FIT_RATES_DPS), by least squares on the held windows'
means u_i against the table's r_i:

    u_i = s r_i + b - c2 u_i^2 - c3 u_i^3

(linear in s, b, c2, c3); s is folded into rate.scale_dps (u' = u / s, so c2' = c2 s,
c3' = c3 s^2), which makes the slope over the thesis's table (+-20..160 deg/s, the
scale factor's definition) 1 with the rest of the range.

Judged (verification, another schedule and seed): the slope between every two held
rates at least SUBRANGE_MIN_DPS apart, against the scale factor over the thesis's table,
within SUBRANGE_PPM.
"""

from __future__ import annotations

import itertools

import numpy as np

# The fit's table: 20..280 deg/s by 20 (full scale 300), each CW and CCW.
FIT_RATES_DPS = tuple(r * sgn for r in range(20, 300, 20) for sgn in (1, -1))
FIT_DWELL_S = 5.0
# A rest before each rate: the bias's wander is taken out against the rests around each
# rate (as in the verification), its mean level kept (the linearisation acts on it).
FIT_REST_S = 3.0
# A linearisation that moves full scale by more than this is no pickoff's: refused.
MAX_CORRECTION_FS = 0.05
# The thesis's rate table (7.2.4): the scale factor is the slope over it.
THESIS_RANGE_DPS = (20.0, 160.0)
# Sub-ranges judged: every two held rates this far apart or more. Narrower ones measure
# the part's bias instability, not its linearity: the default part's bias wanders by
# about 0.01 deg/s between means 15 s apart whatever their length (flicker), 180 ppm of
# slope over 80 deg/s for each pair, and the worst of some 50 pairs read 500..800 ppm on
# a linear part (seeds 1..3); over 120 deg/s or more, 330..350.
SUBRANGE_MIN_DPS = 120.0
SUBRANGE_PPM = 500.0


def table_steps(rates_dps, dwell_s, rest_s):
    """A rate-table schedule: a rest of rest_s before each rate and after the last, each
    rate for dwell_s."""
    steps = [[2.0, 0]]
    for r in rates_dps:
        steps += [[rest_s, 0], [dwell_s, r]]
    return steps + [[rest_s, 0]]


def bias_between_rests(rates, means):
    """For each held window, the bias there: the mean of the rests just before and after
    it (held windows at rate 0); the rests' own means for the rests."""
    rates = list(rates)
    rest = [k for k, r in enumerate(rates) if r == 0.0]
    out = np.array(means, dtype=float)
    for k, r in enumerate(rates):
        if r == 0.0:
            continue
        before = [j for j in rest if j < k]
        after = [j for j in rest if j > k]
        near = ([before[-1]] if before else []) + ([after[0]] if after else [])
        out[k] = float(np.mean([means[j] for j in near])) if near else 0.0
    return out


def fit(rate_in_dps, mean_out_dps):
    """(s, b, c2, c3) of u + c2 u^2 + c3 u^3 = s r + b over the held rates."""
    r = np.asarray(rate_in_dps, dtype=float)
    u = np.asarray(mean_out_dps, dtype=float)
    if r.size < 6 or np.ptp(r) <= 0.0:
        raise ValueError(f"linearity fit: {r.size} held rates, at least 6 of different "
                         "rates are needed")
    a = np.column_stack([r, np.ones_like(r), -u * u, -u ** 3])
    (s, b, c2, c3), *_ = np.linalg.lstsq(a, u, rcond=None)
    return float(s), float(b), float(c2), float(c3)


def correction_at(c2, c3, u_dps):
    """L(u) / u - 1: the linearisation's relative correction at u."""
    return c2 * u_dps + c3 * u_dps * u_dps


def plausible(c2, c3, full_scale_dps):
    """Whether the linearisation moves full scale (either sign) by less than
    MAX_CORRECTION_FS."""
    return all(abs(correction_at(c2, c3, sg * full_scale_dps)) < MAX_CORRECTION_FS
               for sg in (1.0, -1.0))


def rescaled(values, s, c2, c3):
    """The firmware values with the fit folded in (rate.scale_dps / s, c2 s, c3 s^2) on
    top of any linearisation already in them (the fit was made on its output)."""
    v = dict(values)
    v["rate.scale_dps"] = values["rate.scale_dps"] / s
    c2_old, c3_old = values.get("rate.lin_c2_per_dps", 0.0), values.get("rate.lin_c3_per_dps2", 0.0)
    if c2_old or c3_old:
        raise ValueError("linearity fit: made on an output already linearised")
    v["rate.lin_c2_per_dps"] = c2 * s
    v["rate.lin_c3_per_dps2"] = c3 * s * s
    return v


def linearise(u_dps, c2, c3):
    """L(u), as the firmware forms it."""
    u = np.asarray(u_dps, dtype=float)
    return u + u * u * (c2 + u * c3)


def thesis_slope(rate_in_dps, mean_out_dps):
    """The scale factor: the least-squares slope over the held rates within the thesis's
    table (|r| in THESIS_RANGE_DPS, both signs)."""
    r = np.asarray(rate_in_dps, dtype=float)
    y = np.asarray(mean_out_dps, dtype=float)
    m = (np.abs(r) >= THESIS_RANGE_DPS[0] - 1e-9) & (np.abs(r) <= THESIS_RANGE_DPS[1] + 1e-9)
    if np.count_nonzero(m) < 2 or np.ptp(r[m]) <= 0.0:
        raise ValueError("scale factor: fewer than two held rates within +-20..160 deg/s")
    return float(np.polyfit(r[m], y[m], 1)[0])


def subrange_slopes(rate_in_dps, mean_out_dps, se_dps, min_span_dps=None):
    """Every two held rates at least min_span_dps apart: their slope against the scale
    factor over the thesis's table, in ppm, with its standard error from the means'.
    Returns (rows, scale factor), the rows sorted worst first."""
    sf = thesis_slope(rate_in_dps, mean_out_dps)
    min_span_dps = SUBRANGE_MIN_DPS if min_span_dps is None else min_span_dps
    rows = []
    pts = list(zip(rate_in_dps, mean_out_dps, se_dps))
    for (ra, ya, ea), (rb, yb, eb) in itertools.combinations(pts, 2):
        span = rb - ra
        if abs(span) < min_span_dps:
            continue
        slope = (yb - ya) / span
        rows.append({"from_dps": float(min(ra, rb)), "to_dps": float(max(ra, rb)),
                     "slope_ppm": float((slope / sf - 1.0) * 1e6),
                     "se_ppm": float(np.hypot(ea, eb) / abs(span) / sf * 1e6)})
    rows.sort(key=lambda x: -abs(x["slope_ppm"]))
    return rows, sf
