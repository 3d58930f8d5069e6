"""Demodulation-phase and scale-factor calibration from a rate-table log (thesis ch. 5,
7.2.4; system spec section 5).

The firmware forms R = S conj(D) e^{-j phi_dm} / |D|^2 from the sense and drive phasors
and outputs rate = scale Re(R_f), quad = scale Im(R_f) (firmware/gyro/rate_channel.h).
With the demodulation phase off by d_phi, a change of input rate moves the output
vector (rate, quad) along the direction d_phi instead of along the rate axis, and the
large quadrature (about 1500 deg/s) leaks into rate as Q sin(d_phi): 0.01 deg of
phase error is 0.26 deg/s of bias.

Per constant-rate segment the means of (rate_dps, quad_dps) are taken; a least-squares
line through them against the applied rate gives the response vector v = dv/d(rate) =
|v| e^{j alpha}. The corrected parameters are

    rate.demod_phase_deg  <-  phi_dm + alpha
    rate.scale_dps        <-  scale / |v|

and the residual leakage left by the estimate is |sin(std error of alpha)|. Using both
CW and CCW rates cancels the bias and the quadrature itself out of the slope.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from . import scalefactor
from .errors import InputError


@dataclasses.dataclass
class DemodCal:
    alpha_deg: float          # angle of the rate response in the output frame
    alpha_se_deg: float       # its standard error from the fit
    gain: float               # |v|: output deg/s per input deg/s
    phase_deg: float          # corrected rate.demod_phase_deg
    scale_dps: float          # corrected rate.scale_dps
    leakage_bound: float      # |sin(alpha_se)|: quadrature-to-rate leakage left
    quad_dps: float           # quadrature at zero rate, in the corrected frame
    n_segments: int


def calibrate(rates, mean_rate, mean_quad, phase_deg, scale_dps):
    """Fit the response vector through segment means; return the corrected parameters."""
    x = np.asarray(rates, dtype=float)
    if x.size < 2 or np.ptp(x) <= 0.0:
        raise InputError("need at least two different table rates")
    z = np.asarray(mean_rate, dtype=float) + 1j * np.asarray(mean_quad, dtype=float)
    a = np.vstack([np.ones_like(x), x]).T
    coef, *_ = np.linalg.lstsq(a, z, rcond=None)
    b, v = coef[0], coef[1]
    if abs(v) == 0.0:
        raise InputError("the output does not respond to the rate")
    resid = z - a @ coef
    dof = max(x.size - 2, 1)
    s2 = float(np.sum(np.abs(resid) ** 2)) / (2 * dof)  # per component
    se_v = math.sqrt(s2 / float(np.sum((x - x.mean()) ** 2)))
    alpha = math.atan2(v.imag, v.real)
    alpha_se = se_v / abs(v)
    new_phase = (phase_deg + math.degrees(alpha) + 180.0) % 360.0 - 180.0
    # Quadrature at zero rate, seen in the corrected frame: rotate b by -alpha, rescale.
    q0 = (b * np.exp(-1j * alpha)).imag / abs(v)
    return DemodCal(alpha_deg=math.degrees(alpha), alpha_se_deg=math.degrees(alpha_se),
                    gain=abs(v), phase_deg=new_phase, scale_dps=scale_dps / abs(v),
                    leakage_bound=abs(math.sin(alpha_se)), quad_dps=float(q0),
                    n_segments=int(x.size))


def align(t_s, rate_dps, quad_dps, table):
    """Where the table's schedule starts: its step edges in the output's principal
    direction (the response lies along alpha, whatever the demodulation phase's error)."""
    xy = np.column_stack([np.asarray(rate_dps, dtype=float), np.asarray(quad_dps, dtype=float)])
    xy -= xy.mean(axis=0)
    _, _, vt = np.linalg.svd(xy, full_matrices=False)
    return scalefactor.align_table(t_s, xy @ vt[0], table, signed=False)[0]


def analyse(t_s, rate_dps, quad_dps, phase_deg, scale_dps, rate_true_dps=None, table=None,
            t0_s=None, settle_s=1.0, min_avg_s=1.0):
    t_s = np.asarray(t_s, dtype=float)
    if rate_true_dps is not None:
        win = scalefactor.windows_from_truth(t_s, rate_true_dps, settle_s, min_avg_s)
    elif table is not None:
        if t0_s is None:
            t0_s = align(t_s, rate_dps, quad_dps, table)
        win = scalefactor.windows_from_table(t_s, table, t0_s, settle_s, min_avg_s)
    else:
        raise InputError("the log has no rate_true_dps column: give the table schedule "
                         "(--table RATE:DWELL,...)")
    if len(win) < 2:
        raise InputError(f"found {len(win)} usable constant-rate segments, need 2 or more")
    r = scalefactor.segment_means(t_s, np.asarray(rate_dps, dtype=float), win)
    q = scalefactor.segment_means(t_s, np.asarray(quad_dps, dtype=float), win)
    return calibrate([s.rate_in_dps for s in r], [s.mean_out for s in r],
                     [s.mean_out for s in q], phase_deg, scale_dps)
