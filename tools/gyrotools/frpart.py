"""The force-rebalance part of the closed-loop sense tests (tests/closed_loop/
test_cl_sense_fr.c, tests/support/sense_mode_model.h) as gyro-sim --set arguments: the
plant's sense mode and feedback electrodes, and the firmware's model of them as an
identification would give it, from the plant's own values.

    args = fr_args(exe, cal_path, scheme="half", f_sense_hz=1600, q_sense=1e4)

The model (sense_fr.h): rate.demod_phase_deg and rate.scale_dps of the part's calibration
moved by the sense mode's static response at the drive frequency (the mode's phase and gain
at wc, thesis (2-24)), sense.fb_gain_v_per_v2 from the electrode (the feedback force Ks_fb
per V^2 balances the Coriolis force 2 Omega A0 wc), sense.f0_hz and sense.q the mode's.

matched=True: the same part with tuning electrodes (plant tune_ke_per_s2_per_v2 TUNE_KE,
tests/closed_loop/test_cl_sense_tune.c's) tuned onto the drive (sense.tune 1), with the
tuning calibration a sweep with sense.cal 1 stages (sense.cal_s0_hz, sense.cal_tune_ref_hz,
sense.cal_tune_ke_per_s2_per_v2; cal.ref_tune_v the voltage of the tuning's DAC code) and
the model at the resonance that code gives (matched_values; as
tests/closed_loop/check_rate_bandwidth.py --fr-matched stages it).

The two schemes (sense.fb_scheme): "half" the half-frequency pair (plant fb_mode 3, force
Ks A^2 at wc from A at wc / 2, (6-18)), "dcac" the DC+AC pair (plant fb_mode 2, the bias
fb_bias_v +- the AC voltage, force 4 Ks Vb u, (6-20)). Under DC+AC the bias softens the
sense spring, k_e / m = 4 Ks Vb^2 / gap ((6-3), plant_fb_softening, only with a gap
fb_gap_m > 0): the mode the loop sees rings at sqrt(ws^2 - k_e / m), and that softened
resonance is the model's f0 and the one whose response moves the phase and scale.
"""

from __future__ import annotations

import json
import math
import subprocess

KS_FB = 0.1  # (m/s^2)/V^2: 1500 deg/s of quadrature at 7 V (sense_mode_model.h)
TUNE_KE = 2.4e5  # (1/s^2)/V^2: test_cl_sense_tune.c's tuning electrodes, matched at 7.5 V
DAC_V_PER_CODE = 30.0 / 16384  # board.h: 14 bits over +-15 V
FB_MODE = {"half": 3, "dcac": 2}
FB_SCHEME = {"half": 0, "dcac": 1}


def mode_response(f_hz, q, wc):
    """|H| (1/(rad/s)^2) and arg H of a mode at f_hz of quality q driven at wc (2-24)."""
    ws = 2.0 * math.pi * f_hz
    h = 1.0 / complex(ws * ws - wc * wc, wc * ws / q)
    return abs(h), math.atan2(h.imag, h.real)


def plant_values(exe, sets=()):
    """The plant's values gyro-sim would run with (its preset, then the plant --set
    arguments in sets), by name: from a run of 0.01 s's JSON."""
    import os
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "p.json")
        scen = os.path.join(tmp, "s.json")
        with open(scen, "w", encoding="utf-8") as f:
            json.dump({"name": "params", "duration_s": 0.01, "mode": "closed_loop"}, f)
        cmd = [exe, "--scenario", scen, "--no-analysis", "--quiet", "--json", out]
        for s in sets:
            cmd += ["--set", s]
        subprocess.run(cmd, check=True, capture_output=True, text=True)
        with open(out, encoding="utf-8") as f:
            return json.load(f)["params"]


def softened_f_hz(p):
    """The sense resonance with the feedback bias's softening (plant_fb_softening):
    sqrt(ws^2 - 4 Ks Vb^2 / gap) / 2 pi under fb_mode 2 with a gap, else f_sense_hz."""
    ws = 2.0 * math.pi * p["f_sense_hz"]
    ke = 0.0
    if int(p["fb_mode"]) == 2 and p.get("fb_gap_m", 0.0) > 0.0:
        ke = 4.0 * p["ks_fb_mps2_per_v2"] * p["fb_bias_v"] ** 2 / p["fb_gap_m"]
    return math.sqrt(ws * ws - ke) / (2.0 * math.pi)


def matched_values(cal, p):
    """Part p (plant values by name, with tuning electrodes) tuned onto the drive frequency
    of the calibration cal: the tuning calibration a sweep stages, both resonances moved
    by the same factor to the temperature where the drive's is cal's drive.freq_hz (2-32:
    it over the plant's f_drive_hz); the voltage for the target on the DAC's code. Returns
    (the staged values by name, the resonance f0 the code gives, its Q: the damping
    stays, so Q goes as f0)."""
    f_ref = cal["drive.freq_hz"]
    ke = p["tune_ke_per_s2_per_v2"]
    s0 = softened_f_hz(p) * f_ref / p["f_drive_hz"]
    w0, wt = 2.0 * math.pi * s0, 2.0 * math.pi * f_ref
    if not (ke > 0.0 and w0 > wt):
        raise ValueError("the part cannot be tuned onto its drive (no tuning electrodes, or "
                         "its sense resonance at or below the drive's)")
    v = round(math.sqrt((w0 * w0 - wt * wt) / ke) / DAC_V_PER_CODE) * DAC_V_PER_CODE
    f_t = math.sqrt(w0 * w0 - ke * v * v) / (2.0 * math.pi)
    staged = {"sense.tune": 1, "sense.cal_s0_hz": s0, "sense.cal_tune_ref_hz": f_ref,
              "sense.cal_tune_ke_per_s2_per_v2": ke, "cal.ref_tune_v": v}
    return staged, f_t, p["q_sense"] * f_t / s0


def model_values(cal, p_base, p, f0=None, q=None):
    """The firmware's model of part p (plant values by name) from the calibration cal
    (name -> value) made on p_base, the part without the force-rebalance changes; its mode
    at f0 of quality q (default: p's own, softened_f_hz and q_sense)."""
    wc = 2.0 * math.pi * cal["drive.freq_hz"]
    f0 = softened_f_hz(p) if f0 is None else f0
    q = p["q_sense"] if q is None else q
    m0, a0 = mode_response(p_base["f_sense_hz"], p_base["q_sense"], wc)
    m1, a1 = mode_response(f0, q, wc)
    # the pickoff's gain (V/m) divides the scale as the mode's gain does
    g_pick = p_base["pick_sense_gain_v_per_m"] / p["pick_sense_gain_v_per_m"]
    scale = cal["rate.scale_dps"] * m0 / m1 * g_pick
    # rate per V^2 of force, Ks_fb / (2 A0 wc) (plant_fb_rate_dps_per_v2)
    k_dps_per_v2 = p["ks_fb_mps2_per_v2"] / (2.0 * p["drive_amp_m"] * wc) * 180.0 / math.pi
    return {"rate.demod_phase_deg": cal["rate.demod_phase_deg"] + math.degrees(a1 - a0),
            "rate.scale_dps": scale,
            "sense.fb_gain_v_per_v2": k_dps_per_v2 / scale * cal["drive.amp_set_v"],
            "sense.f0_hz": f0, "sense.q": q, "sense.mode": 1,
            # the calibration moved by the model is force rebalance's (gyro_design.c:
            # another sense configuration's is stale)
            "cal.ref_sense_mode": 1}


def fr_args(exe, cal_path, scheme="half", f_sense_hz=1600.0, q_sense=1e4, plant=None,
            base=(), matched=False, model=True):
    """gyro-sim --set arguments of the force-rebalance part: base (plant --set strings of
    the part the calibration cal_path was made on, its preset included), then the sense
    mode at f_sense_hz of quality q_sense, the feedback pair of scheme at KS_FB, then
    plant (name -> value, e.g. fb_gap_m, noise settings); the firmware's model from
    model_values. matched: with tuning electrodes of TUNE_KE, tuned onto the drive
    (matched_values). model=False: the plant's arguments alone (the part's own
    calibration, e.g. from tools/calibrate --sense fr, supplies the firmware's values)."""
    if scheme not in FB_MODE:
        raise ValueError(f"scheme {scheme!r}: half or dcac")
    fr = {"f_sense_hz": f_sense_hz, "q_sense": q_sense, "fb_mode": FB_MODE[scheme],
          "ks_fb_mps2_per_v2": KS_FB,
          **({"tune_ke_per_s2_per_v2": TUNE_KE} if matched else {}), **(plant or {})}
    sets = list(base) + [f"plant.{k}={v:.9g}" for k, v in fr.items()]
    if not model:
        return [a for s in sets for a in ("--set", s)]
    p_base = plant_values(exe, base)
    p = plant_values(exe, sets)
    with open(cal_path, encoding="utf-8") as f:
        cal = {e["name"]: e["value"] for e in json.load(f)["params"]}
    if matched:
        staged, f_t, q_t = matched_values(cal, p)
        fw = {**model_values(cal, p_base, p, f_t, q_t), **staged}
    else:
        fw = model_values(cal, p_base, p)
    fw["sense.fb_scheme"] = FB_SCHEME[scheme]
    args = []
    for s in sets:
        args += ["--set", s]
    for k, v in fw.items():
        args += ["--set", f"firmware.{k}={v:.9g}"]
    return args
