"""The compensation's thermometer filter against its noise and its ramp residual
(tools/comp_filter_study, docs/compensation-noise.md).

The firmware compensates rate = u SF(x) - B(x) - k_g h with x = P_c - cal.ref_p_deg and
P_c the thermometer P_f through rate.comp_stages first-order low-passes of
rate.comp_tau_s each (thermcal). P_f's noise is mostly the drive pickoff's phase
flicker (1/f): the compensation passes it on at the bias slope, so the filter trades the
output's noise at 10 s against the lag it puts into a ramp (which the gradient term,
fitted with the filter in place, takes back only where the ramp is steady).

For each filter this module refits the compensation on a calibration run's log as the
flow does (thermcal.fit) and applies it offline, as the firmware would, to logs of other
runs: a heating ramp (1 s means of the bias at rest, their std), chamber plateaus (the
bias at rest), and a run at constant temperature (Allan deviation of the compensated
output against rate_unc_dps at 1, 10, 100, 1000 s). P_f in a log does not depend on
the compensation, so one set of runs serves every filter. The offline output is the
firmware's formula on the logged 10 or 100 Hz rows (P_f updates at 500 Hz), not a
firmware run: a filter it picks is confirmed by the flow's own verification.
"""

from __future__ import annotations

import numpy as np

from . import allan, thermcal

TAUS_S = (1.0, 10.0, 100.0, 1000.0)


def _bias(v, x):
    return v["rate.bias_c0_dps"] + x * (v["rate.bias_c1_dps_per_deg"] + x * (
        v["rate.bias_c2_dps_per_deg2"] + x * v["rate.bias_c3_dps_per_deg3"]))


def static_parts(log, v, comp_tau_s, comp_stages):
    """The compensation's scale factor and static bias (its cubic in x = P_c -
    cal.ref_p_deg, without the gradient term and the fast path) at each row: (sf, b)."""
    p_c = thermcal.comp_thermometer(log["t_s"], log["p_f_deg"], comp_tau_s, comp_stages)
    x = p_c - v["cal.ref_p_deg"]
    sf = 1.0 + x * (v["rate.sf_c1_per_deg"] + x * (v["rate.sf_c2_per_deg2"] + x * (
        v["rate.sf_c3_per_deg3"] + x * v["rate.sf_c4_per_deg4"])))
    return sf, _bias(v, x)


def compensate(log, v, comp_tau_s, comp_stages):
    """The firmware's output from a log's rate_unc_dps and P_f for the values v
    (rate.*, cal.ref_p_deg) and the filter (comp_tau_s, comp_stages); with
    rate.comp_fast_tau_s > 0 in v, blended with the fast path as
    rate_channel_comp_refresh does."""
    t = log["t_s"]
    p_c = thermcal.comp_thermometer(t, log["p_f_deg"], comp_tau_s, comp_stages)
    x = p_c - v["cal.ref_p_deg"]
    h = thermcal.gradient_hp(t, p_c, v["rate.grad_tau_s"])
    sf = 1.0 + x * (v["rate.sf_c1_per_deg"] + x * (v["rate.sf_c2_per_deg2"] + x * (
        v["rate.sf_c3_per_deg3"] + x * v["rate.sf_c4_per_deg4"])))
    b = _bias(v, x) + v["rate.bias_grad_dps_per_deg"] * h
    tau_f = v.get("rate.comp_fast_tau_s", 0.0)
    if tau_f > 0.0:
        p_f = thermcal.comp_thermometer(t, log["p_f_deg"], tau_f, 1)
        h_f = thermcal.gradient_hp(t, p_f, v["rate.grad_tau_s"])
        d = _bias(v, p_f - v["cal.ref_p_deg"]) + v["rate.grad_fast_dps_per_deg"] * h_f - b
        blend = v["rate.comp_blend_dps"]
        b = b + np.clip((np.abs(d) - blend) / blend, 0.0, 1.0) * d
    return np.asarray(log["rate_unc_dps"]) * sf - b


class _View(dict):
    """A log with one column replaced (thermcal's verifications read log[name])."""


def _with_rate(log, names, rate):
    d = _View({n: np.asarray(log[n]) for n in names})
    d["rate_dps"] = rate
    return d


def adev_at(rate_dps, fs_hz, taus=TAUS_S):
    """Overlapping Allan deviation (deg/h) at the taus the record holds (nan beyond)."""
    c = allan.adev_curve(rate_dps, fs_hz, per_decade=20, max_frac=0.34)
    return [float(np.interp(tau, c.tau_s, c.adev_dph)) if tau <= c.tau_s[-1] else float("nan")
            for tau in taus]


def evaluate(cal, ramp, plateaus, noise, comp_tau_s, comp_stages, proto=thermcal.FULL):
    """One filter: refit on the calibration log `cal`, judge on the others. Returns the
    fit's values and the figures (ramp std, plateau biases, noise ratios)."""
    v, _, figs = thermcal.fit(cal, proto.cal_plateaus_c, proto.dwell_s, proto.span_from_data,
                              comp_tau_s=comp_tau_s, comp_stages=comp_stages)
    cols = ("t_s", "rate_true_dps", "rate_valid", "t_struct_c", "p_f_deg")
    r = thermcal.verify_ramp(_with_rate(ramp, cols, compensate(ramp, v, comp_tau_s,
                                                                comp_stages)), proto)
    pl = thermcal.verify_plateaus(_with_rate(plateaus, cols, compensate(
        plateaus, v, comp_tau_s, comp_stages)), proto.verify_plateaus_c, proto.dwell_s)
    t = noise["t_s"]
    m = t >= 2 * thermcal.START_S
    fs = 1.0 / float(np.median(np.diff(t)))
    a_c = adev_at(compensate(noise, v, comp_tau_s, comp_stages)[m], fs)
    a_u = adev_at(np.asarray(noise["rate_unc_dps"])[m], fs)
    return {"comp_tau_s": comp_tau_s, "comp_stages": comp_stages,
            "grad_tau_s": v["rate.grad_tau_s"], "grad_k_dps_per_deg": v["rate.bias_grad_dps_per_deg"],
            "bias_c1_dps_per_deg": v["rate.bias_c1_dps_per_deg"],
            "fit_rms_1s_dps": figs["fit_rms_1s_dps"],
            "ramp_bias_1s_std_dps": r["bias_1s_std_dps"],
            "ramp_bias_1s_max_abs_dps": r["bias_1s_max_abs_dps"],
            "plateau_bias_dps": [p["bias_dps"] for p in pl],
            "taus_s": list(TAUS_S), "adev_compensated_dph": a_c, "adev_uncompensated_dph": a_u,
            "noise_ratio": [c / u for c, u in zip(a_c, a_u)]}
