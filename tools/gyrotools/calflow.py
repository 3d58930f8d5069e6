"""The calibration flow of a fresh part against the simulator (tools/calibrate).

Stages, each a separate gyro-sim run on the same part (--set plant.KEY=V) from the
firmware's generic defaults:

1. self-calibration: the firmware's own `sweep` identifies the drive resonance, Q, gain
   and the force phase at resonance (gyro-sim --selfcal, saved as a user would);
2. rate table, CW and CCW (host_sim/scenarios/rate_table.json: +-20..160 deg/s, the
   thesis's table 7-2): the response's direction and length in the output frame give
   the demodulation phase and the scale factor (gyrotools.demodcal); repeated with the
   corrected values until the response lies on the rate axis with unit gain;
3. linearity (gyrotools.lincal): a rate table over the full scale, CW and CCW; the
   output's linearisation, a cubic in the uncompensated rate, with its slope folded into
   the scale so that the slope over the thesis's table stays 1;
4. thermal calibration (gyrotools.thermcal): chamber plateaus over -40..85 degC with rate
   steps at each plateau's end; bias and scale-factor cubics in the thermometer's
   deviation from its reference (cal.ref_p_deg), the gradient term of the transients,
   the thermometer's range;
5. self-test expectations: the on-demand test's response and the continuous test's
   amplitude on the calibrated part at rest (scenario "commands": `selftest`, `status`),
   at the drive setpoint (selftest.ref_amp_v);
6. the calibration record: every value the firmware holds for this part, with
   cal.ref_freq_hz (the drive frequency it was made at), cal.ref_track (the drive mode
   it was made in), cal.ref_sense_mode and cal.ref_quad_null (the sense configuration),
   cal.part_id and cal.date,
   written as a param set (gyrotools.paramset);
7. verification on profiles the fit never saw, each with its own noise seed, run side by
   side: another rate schedule (+-30..270 deg/s, other dwell), judged on the rate output
   the firmware marks valid where the input is held: scale factor over the thesis's
   range, the slope over every sub-range of at least lincal.SUBRANGE_MIN_DPS, bias at
   rest, never a valid rate off by more than VERIFY_MAX_ERR_DPS, then the on-demand
   self-test at rest passes; other chamber plateaus, a heating ramp, a fast transient,
   a cold start (the warm-up) and the noise with the compensation (thermcal: limits in
   thermcal.LIMITS).
"""

from __future__ import annotations

import concurrent.futures
import dataclasses
import datetime
import json
import math
import os
import subprocess
import zlib

import numpy as np

from . import boardcal, compstudy, csvlog, demodcal, fields, lincal, paramset, scalefactor, thermcal
from .errors import InputError

# Rate-table iterations: the demodulation is linear in the phasors, so one pass is exact
# but for the noise; the second pass measures what is left, a third only if needed.
MAX_PASSES = 3
# The rate table's result is taken when its response lies within these of the rate axis
# and unit gain (0.002 deg: 0.05 deg/s of the 1500 deg/s quadrature; 20 ppm of scale).
ALPHA_TOL_DEG = 0.002
GAIN_TOL = 20e-6
# Verification limits (issue: scale factor within +-500 ppm; bias at rest as the output
# integrity's tolerance of 1 deg/s for any valid sample).
VERIFY_SF_PPM = 500.0
VERIFY_BIAS_DPS = 0.5
VERIFY_MAX_ERR_DPS = 1.0
VERIFY_VALID_FRAC = 0.9
# The verification's schedule: rates the fit never saw, another dwell.
# Noise seeds of the stages, from --seed: the rate table's passes +100, +101, ...; the
# verification +1000; none is a seed a shipped scenario uses, so that no figure a
# scenario reports is measured on the noise a calibration was fitted to.
RATE_TABLE_SEED_OFFSET = 100
THERMAL_SEED_OFFSET = 200
VERIFY_SEED_OFFSET = 1000
# The thermal verification's runs: plateaus, ramp, noise at +1001, +1002, +1003.
# The self-test's response below this is no working self-test (the design's electrodes
# give about 5.5 deg/s at selftest.amp_v 0.1 V; dead ones, their feedthrough, 0.05).
SELFTEST_MIN_DPS = 1.0
# The lost-match monitor's zero beyond this is no tuned part: the model's own offset
# measured 0.7-1.35 Hz at the default 250 Hz tone, 6.8 Hz at a 500 Hz tone
# (tests/slow/test_tune_disc_study.c); its tolerance about the zero is 3.7 Hz.
DISC_ZERO_MAX_HZ = 10.0
VERIFY_RATES_DPS = (30, -30, 70, -70, 110, -110, 150, -150, 190, -190, 230, -230, 270, -270)
# The sub-range slopes are judged between the means of ~50 pairs, so their noise must
# be a fraction of the limit; the part's bias wanders (flicker, drifts) by hundredths of
# a deg/s over minutes, so each rate is measured against the rests on either side of it
# (IEEE 1431's rate transfer test): with 4 s dwells and no rests the default part,
# linear, read 508 ppm over 150..230 deg/s, with 15 s dwells 463.
VERIFY_DWELL_S = 10.0
VERIFY_REST_S = 5.0
# The part's start-up before a verification schedule (startup_lead_s): the rate
# reference's wide start of RATE_REF_WIDE_TAUS (rate_channel.h) drive time constants, and
# a margin for the lock and the output filters.
START_TAUS = 4.0
START_MARGIN_S = 2.0
LINEARITY_SEED_OFFSET = 150
SETTLE_S = scalefactor.SETTLE_S_DEFAULT
MIN_AVG_S = scalefactor.MIN_AVG_S_DEFAULT


class FlowError(Exception):
    """A stage failed: the message says which and why (exit code 1 of tools/calibrate)."""


@dataclasses.dataclass
class SimPart:
    gyro_sim: str
    scenarios: str  # host_sim/scenarios
    sets: list      # ["plant.KEY=V", ...]
    seed: int
    work: str       # folder for the stages' files
    protocol: thermcal.Protocol = thermcal.FULL  # the thermal profiles (--quick: QUICK)
    port: object = None  # a calport.PortTarget: the stages run on a part behind a UART
    # the sense configuration calibrated (sense_config): firmware name -> value, set
    # before the sweep; the later stages inherit it through the param sets
    config: dict = dataclasses.field(default_factory=dict)
    # the board thermometer (tools/calibrate --board-temp): its model of the bias fitted
    # on the chamber run and fused with P (board.fuse 1, gyrotools/boardcal.py)
    board: bool = False


# The sense configurations the flow calibrates (tools/calibrate --sense, --fb-scheme,
# --quad-null, --tune): a calibration holds in the configuration it was made in only
# (cal.ref_sense_mode, cal.ref_quad_null, cal.ref_tune_v; gyro_design.c).
SENSE_MODES = {"open": 0, "fr": 1}
FB_SCHEMES = {"half": 0, "dcac": 1}
TUNE_MODES = {"off": 0, "matched": 1, "split": 2}


def sense_config(sense="open", fb_scheme=None, quad_null=False, tune="off"):
    """The firmware settings of a sense configuration, by name: force rebalance (with its
    feedback scheme), quadrature nulling, mode tuning. The sweep identifies the sense
    mode (sense.cal 1) whenever force rebalance or tuning needs its model. Raises
    InputError for a combination the firmware refuses (matched tuning is force
    rebalance's: open loop, a matched mode rings for seconds, issue 19)."""
    if sense not in SENSE_MODES or tune not in TUNE_MODES or \
            (fb_scheme is not None and fb_scheme not in FB_SCHEMES):
        raise InputError(f"sense configuration {sense!r}, {fb_scheme!r}, {tune!r}: "
                         f"--sense {'|'.join(SENSE_MODES)}, --fb-scheme "
                         f"{'|'.join(FB_SCHEMES)}, --tune {'|'.join(TUNE_MODES)}")
    if fb_scheme is not None and sense != "fr":
        raise InputError("--fb-scheme chooses force rebalance's feedback electrodes: "
                         "it needs --sense fr")
    if tune == "matched" and sense != "fr":
        raise InputError("--tune matched needs --sense fr (the firmware runs a matched "
                         "part in force rebalance only)")
    cfg = {}
    if sense == "fr":
        cfg["sense.mode"] = 1
        cfg["sense.fb_scheme"] = FB_SCHEMES[fb_scheme or "half"]
    if quad_null:
        cfg["quad.null"] = 1
    if tune != "off":
        cfg["sense.tune"] = TUNE_MODES[tune]
    if sense == "fr" or tune != "off":
        cfg["sense.cal"] = 1
    return cfg


def force_rebalance(values):
    """The values run force rebalance (sense.mode 1)."""
    return int(values.get("sense.mode", 0)) == 1


def shown_path(path):
    """A path as a command recorded in the report shows it: relative to the folder the
    flow runs in when it lies below it (as the flow's own command line is written), so
    that the report reads the same in every clone; absolute otherwise."""
    rel = os.path.relpath(path)
    return path if rel == ".." or rel.startswith(".." + os.sep) else rel


def _run(part, args, what):
    cmd = [part.gyro_sim] + args
    for s in part.sets:
        cmd += ["--set", s]
    r = subprocess.run(cmd, capture_output=True, text=True)
    cmd = [shown_path(a) if os.path.isabs(a) else a for a in cmd]
    if r.returncode != 0:
        msg = (r.stderr.strip() or r.stdout.strip()).splitlines()
        raise FlowError(f"{what}: gyro-sim exit {r.returncode}: "
                        f"{msg[-1] if msg else 'no message'}\n  command: {' '.join(cmd)}")
    return cmd


def _scenario(part, name, doc):
    """A scenario of the flow's own, in the work folder: the shipped scenarios name the
    default part's calibration, and a fresh part has none."""
    path = os.path.join(part.work, name + "_scenario.json")
    with open(path, "w", encoding="utf-8") as fh:
        json.dump(dict(doc, name=name, mode="closed_loop", seed=part.seed, analyses=[]), fh,
                  indent=1)
    return path


def selfcal(part):
    """Stage 1: the firmware's sweep from its generic defaults -> a param set."""
    out = os.path.join(part.work, "selfcal_params.json")
    if part.port is not None:
        f = part.port.selfcal(out, part.config)
        return out, {"command": part.port.describe("sweep"), "f0_hz": f["selfcal_f0_hz"],
                     "q": f["selfcal_q"], "s": f["selfcal_s"], "true_f0_hz": None,
                     "true_q": None}
    figs = os.path.join(part.work, "selfcal.json")
    scen = _scenario(part, "calibrate_selfcal", {
        "description": "a fresh part's self-calibration from the firmware's generic defaults",
        "duration_s": 0.2, "selfcal": True})
    config = []
    for k, v in part.config.items():
        config += ["--set", f"firmware.{k}={v}"]
    cmd = _run(part, ["--scenario", scen, "--seed", str(part.seed), "--no-analysis", "--quiet",
                      "--save-params", out, "--json", figs] + config, "self-calibration")
    with open(figs, encoding="utf-8") as fh:
        f = json.load(fh)["figures"]
    res = {"command": " ".join(cmd), "f0_hz": f.get("selfcal_f0_hz"),
           "q": f.get("selfcal_q"), "s": f.get("selfcal_s"),
           "true_f0_hz": f.get("selfcal_true_f0_hz"), "true_q": f.get("selfcal_true_q")}
    if part.config.get("sense.cal"):
        res["sense"] = _sense_identified(f, part.config)
    if part.config.get("sense.tune") and not paramset.read(out).values().get("sense.cal_s0_hz"):
        raise FlowError("self-calibration: mode tuning asked for, but the sweep did not tune "
                        "the part (its sense resonance at or below the target, or no match "
                        "within the tuning electrodes' reach)")
    return out, res


def _sense_identified(f, config):
    """The sweep's sense identification (sense.cal 1) from gyro-sim's figures, beside the
    plant's truth; a configuration that needs the model fails the stage without it."""
    keys = ("f0_hz", "q", "fb_gain_v_per_v2", "fb_phase_deg", "tune_ke_per_s2_per_v2")
    res = {"identified": bool(f.get("selfcal_sense_identified")), "s": f.get("selfcal_sense_s")}
    for k in keys:
        res[k] = f.get("selfcal_sense_" + k)
        res["true_" + k] = f.get("selfcal_true_sense_" + k)
    if not res["identified"]:
        raise FlowError("self-calibration: the sense mode was not identified ("
                        f"{f.get('selfcal_sense_why') or 'no reason given'}); the "
                        "configuration asked for needs its model")
    if config.get("sense.tune") and not res["tune_ke_per_s2_per_v2"]:
        raise FlowError("self-calibration: mode tuning asked for, but the sweep found no "
                        f"tuning slope ({f.get('selfcal_sense_tune_why') or 'no reason given'})")
    return res


# The fixed drive's reach (gyro/selfcal.h SELFCAL_Q_FIXED_MAX): above it the sweep commits
# the tracking drive, and gyro_design refuses the fixed one.
FIXED_Q_MAX = 5000.0
DRIVES = ("auto", "fixed", "tracking")


def choose_drive(part, sc_path, drive, q):
    """The drive mode the later stages calibrate: the sweep's choice ("auto"), or the one
    asked for, written into a copy of the self-calibration's param set. Returns its path."""
    if drive not in DRIVES:
        raise FlowError(f"drive mode {drive!r}: one of {', '.join(DRIVES)}")
    if drive == "auto":
        return sc_path
    if drive == "fixed" and not q <= FIXED_Q_MAX:
        raise FlowError(f"--drive fixed: the part's Q {q:.0f} is beyond the fixed drive's "
                        f"{FIXED_Q_MAX:g} (its sweep chose the tracking drive)")
    ps = paramset.read(sc_path)
    values = ps.values()
    values["drive.track"] = 1 if drive == "tracking" else 0
    out = os.path.join(part.work, f"selfcal_{drive}_params.json")
    paramset.write(out, paramset.from_values(values, meta=ps.meta))
    return out


LOG_COLUMNS = ["rate_dps", "quad_dps", "rate_true_dps", "rate_valid", "rate_invalid"]
THERMAL_COLUMNS = LOG_COLUMNS + ["rate_unc_dps", "p_f_deg"]
# The simulator's truth, read where logged (a part on a port has none of it).
TRUTH_COLUMNS = ("t_struct_c",)


def _on_port(part, params, scenario, name, csv, columns):
    """One run of a part on a port (calport): as _sim."""
    with open(scenario, encoding="utf-8") as fh:
        scen = json.load(fh)
    log_path = os.path.join(part.work, name + ".csv")
    replies = part.port.run(params, scen, log_path)
    log = csvlog.read_log(log_path, need=columns or LOG_COLUMNS, want=TRUTH_COLUMNS,
                          purpose=name) if csv else None
    return log, replies, part.port.describe(f"{shown_path(scenario)} from {shown_path(params)}")


def _sim(part, params, scenario, seed, name, csv=False, columns=None):
    """One gyro-sim run from the param set `params`: (its CSV log or None, the replies to
    the scenario's "commands", the command line)."""
    if part.port is not None:
        return _on_port(part, params, scenario, name, csv, columns)
    js = os.path.join(part.work, name + ".json")
    args = ["--scenario", scenario, "--firmware-params", params, "--seed", str(seed),
            "--no-analysis", "--quiet", "--json", js]
    log_path = os.path.join(part.work, name + ".csv")
    cmd = _run(part, args + (["--csv", log_path] if csv else []), name)
    log = csvlog.read_log(log_path, need=columns or LOG_COLUMNS, want=TRUTH_COLUMNS,
                          purpose=name) if csv else None
    with open(js, encoding="utf-8") as fh:
        replies = [c["reply"] for c in json.load(fh).get("commands", [])]
    return log, replies, " ".join(cmd)


# The rate table's run is judged from where the drive is LOCKED for good: before, P and the
# demodulated phasors are the acquisition's (on thesis-preset parts of Q about 3000 the
# fixed drive locks after 2.8 s or more; the fit then read P's turn with the rate squared
# as 0.073 deg/(deg/s)^2 and the part failed). At most this fraction of the run may go.
LOCK_WAIT_MAX = 0.5


def _lock_index(log):
    """The first sample after which the firmware stays LOCKED (no MODE reason): 0 when
    it always was, len(log) when it never is at the end."""
    bit = 1 << fields.RATE_INVALID.index("MODE")
    last = np.flatnonzero((log["rate_invalid"].astype(np.int64) & bit) != 0)
    return 0 if last.size == 0 else int(last[-1]) + 1


def lock_time_s(log):
    """When the firmware is LOCKED for good, from the log's start."""
    t = log["t_s"]
    return float(t[min(_lock_index(log), t.size - 1)] - t[0])


def locked_log(log, what):
    """The log from the first sample after which the firmware stays LOCKED (no MODE
    reason), or the whole log when that is before the first judged window (SETTLE_S):
    air parts (LOCKED at 0.04 s) are judged exactly as before."""
    i = _lock_index(log)
    if i == 0:
        return log
    t = log["t_s"]
    if i >= t.size or t[i] - t[0] > LOCK_WAIT_MAX * (t[-1] - t[0]):
        raise FlowError(f"{what}: the drive was not LOCKED for good before "
                        f"{LOCK_WAIT_MAX:.0%} of the run")
    if t[i] - t[0] <= SETTLE_S:
        return log
    return dataclasses.replace(log, data=log.data[i:])


def rate_table(part, params_path):
    """Stage 2: demodulation phase and scale from rate tables, until the response lies
    on the rate axis. Returns the values and each pass's figures."""
    values = paramset.read(params_path).values()
    passes = []
    scen = os.path.join(part.scenarios, "rate_table.json")
    for k in range(MAX_PASSES):
        cur = os.path.join(part.work, f"rate_table_{k}_params.json")
        paramset.write(cur, paramset.from_values(values, meta={"stage": f"rate table pass {k}"}))
        log, _, cmd = _sim(part, cur, scen, part.seed + RATE_TABLE_SEED_OFFSET + k,
                           f"rate_table_{k}", csv=True, columns=LOG_COLUMNS + ["p_f_deg"])
        lock_s = lock_time_s(log)
        log = locked_log(log, f"rate table pass {k}")
        res = demodcal.analyse(log["t_s"], log["rate_dps"], log["quad_dps"],
                               values["rate.demod_phase_deg"], values["rate.scale_dps"],
                               rate_true_dps=log["rate_true_dps"], settle_s=SETTLE_S,
                               min_avg_s=MIN_AVG_S)
        if not (np.isfinite(res.gain) and res.gain > 0.0) or res.n_segments < 8:
            raise FlowError(f"rate table pass {k}: implausible response "
                            f"(gain {res.gain:.6g}, {res.n_segments} segments)")
        passes.append({"command": cmd, "alpha_deg": res.alpha_deg,
                       "alpha_se_deg": res.alpha_se_deg, "gain": res.gain,
                       "phase_deg": res.phase_deg, "scale_dps": res.scale_dps,
                       "quad_dps": res.quad_dps, "segments": res.n_segments,
                       "lock_s": lock_s})
        values["rate.demod_phase_deg"] = res.phase_deg
        values["rate.scale_dps"] = res.scale_dps
        if int(values.get("sense.mode", 0)) == 1:
            # Force rebalance reads the rate from the force, whose frame is the feedback
            # phase's (firmware/gyro/sense_fr.h): the readout turns with it as it turns
            # with the demodulation phase open loop, and the loop's frame follows.
            values["sense.fb_phase_deg"] = wrap_deg(values["sense.fb_phase_deg"] + res.alpha_deg)
        # The thermometer's reading of the rate (rate.p_rate_deg_per_dps, and with its
        # square rate.p_rate2_deg_per_dps2), on top of what the firmware already took
        # out: P against the table's rate.
        beta, gamma = p_rate_turn(log)
        values["rate.p_rate_deg_per_dps"] += beta
        values["rate.p_rate2_deg_per_dps2"] = values.get("rate.p_rate2_deg_per_dps2", 0.0) + gamma
        passes[-1]["p_rate_deg_per_dps"] = beta
        passes[-1]["p_rate2_deg_per_dps2"] = gamma
        if abs(res.alpha_deg) <= ALPHA_TOL_DEG and abs(res.gain - 1.0) <= GAIN_TOL:
            break
    return values, passes


def _held_means(log, column, t_end_s=np.inf):
    """The held windows' means of a column, up to t_end_s: (rates, means, standard
    errors). The error from the spread of eight sub-window means (the samples are
    correlated)."""
    win = scalefactor.windows_from_truth(log["t_s"], log["rate_true_dps"], SETTLE_S, MIN_AVG_S)
    r, m, se = [], [], []
    for rate, i0, i1 in win:
        i1 = min(i1, int(np.searchsorted(log["t_s"], t_end_s)))
        if i1 - i0 < 8:
            continue
        y = log[column][i0:i1]
        parts = [np.mean(c) for c in np.array_split(y, 8) if c.size]
        r.append(rate)
        m.append(float(np.mean(y)))
        se.append(float(np.std(parts, ddof=1) / np.sqrt(len(parts))) if len(parts) > 1
                  else float("nan"))
    return np.array(r), np.array(m), np.array(se)


def linearity(part, values):
    """Stage 3: the output's linearisation from a full-scale rate table (lincal)."""
    path = os.path.join(part.work, "linearity_params.json")
    paramset.write(path, paramset.from_values(values, meta={"stage": "linearity"}))
    steps = lincal.table_steps(lincal.FIT_RATES_DPS, lincal.FIT_DWELL_S, lincal.FIT_REST_S)
    scen = _scenario(part, "calibrate_linearity", {
        "description": "linearity: a rate table over the full scale, CW and CCW",
        "duration_s": sum(st[0] for st in steps), "csv_rate_hz": 200,
        "rate_dps": {"kind": "steps", "edge_s": 0.1, "steps": steps}})
    log, _, cmd = _sim(part, path, scen, part.seed + LINEARITY_SEED_OFFSET, "linearity",
                       csv=True, columns=LOG_COLUMNS + ["rate_unc_dps"])
    r, u, _ = _held_means(log, "rate_unc_dps")
    held = np.abs(r) > 0.0
    # The bias's wander out, its level kept (the linearisation acts on u, bias and all).
    b_near = lincal.bias_between_rests(r, u)
    u = u - np.where(held, b_near - np.mean(u[~held]), 0.0)
    try:
        s, b, c2, c3 = lincal.fit(r[held], u[held])
    except ValueError as e:
        raise FlowError(f"{e} ({cmd})") from None
    fs = values["rate.full_scale_dps"]
    if not (np.isfinite(s) and s > 0.0 and lincal.plausible(c2, c3, fs)):
        raise FlowError(f"linearity: implausible fit (slope {s:.6g}, c2 {c2:.3g}, c3 {c3:.3g}: "
                        f"more than {100 * lincal.MAX_CORRECTION_FS:g} % at full scale) ({cmd})")
    lin = lincal.linearise(u[held], c2, c3)
    resid_before = u[held] - np.polyval(np.polyfit(r[held], u[held], 1), r[held])
    resid_after = lin - (s * r[held] + b)
    v = lincal.rescaled(values, s, c2, c3)
    return v, {"command": cmd, "seed": part.seed + LINEARITY_SEED_OFFSET,
               "rates_dps": list(lincal.FIT_RATES_DPS), "dwell_s": lincal.FIT_DWELL_S,
               "slope": s, "offset_dps": b, "c2_per_dps": v["rate.lin_c2_per_dps"],
               "c3_per_dps2": v["rate.lin_c3_per_dps2"],
               "correction_at_fs": [lincal.correction_at(c2, c3, fs),
                                    lincal.correction_at(c2, c3, -fs)],
               "residual_rms_dps_linear": float(np.sqrt(np.mean(resid_before ** 2))),
               "residual_rms_dps_linearised": float(np.sqrt(np.mean(resid_after ** 2)))}


def thermal(part, values):
    """Stage 3: the temperature compensation from a chamber run (gyrotools.thermcal)."""
    path = os.path.join(part.work, "thermal_params.json")
    values = dict(values, **{"rate.comp_tau_s": part.protocol.comp_tau_s,
                              "rate.comp_stages": part.protocol.comp_stages,
                              "rate.comp_fast_tau_s": part.protocol.comp_fast_tau_s})
    paramset.write(path, paramset.from_values(values, meta={"stage": "thermal"}))
    temps = part.protocol.cal_plateaus_c
    scen = _scenario(part, "calibrate_thermal", thermcal.plateau_scenario(
        temps, part.protocol.dwell_s,
        {"description": "thermal calibration: chamber plateaus with rate steps at their ends"}))
    log, _, cmd = _sim(part, path, scen, part.seed + THERMAL_SEED_OFFSET, "thermal", csv=True,
                       columns=THERMAL_COLUMNS + (["board_c"] if part.board else []))
    # The compensation acts on the linearised output L(u) (rate_channel.h).
    log.data["rate_unc_dps"] = lincal.linearise(log["rate_unc_dps"],
                                                values.get("rate.lin_c2_per_dps", 0.0),
                                                values.get("rate.lin_c3_per_dps2", 0.0))
    comp, s0, figs = thermcal.fit(log, temps, part.protocol.dwell_s,
                                  part.protocol.span_from_data,
                                  comp_tau_s=part.protocol.comp_tau_s,
                                  comp_stages=part.protocol.comp_stages,
                                  comp_fast_tau_s=part.protocol.comp_fast_tau_s)
    if not (np.isfinite(s0) and s0 > 0.0) or not all(np.isfinite(v) for v in comp.values()):
        raise FlowError(f"thermal calibration: implausible fit (scale {s0:.6g}) ({cmd})")
    v = dict(values)
    v.update(comp)
    v["rate.scale_dps"] = values["rate.scale_dps"] * s0
    v["rate.p_rate_deg_per_dps"] = values["rate.p_rate_deg_per_dps"] + figs["p_turn_c0_deg_per_dps"]
    if part.board:
        v, figs["board"] = board_model(log, v, s0, cmd)
    figs["command"] = cmd
    figs["seed"] = part.seed + THERMAL_SEED_OFFSET
    return v, figs


def board_model(log, v, s0, cmd):
    """The board thermometer's model of the bias (gyrotools/boardcal.py) on the chamber
    run at rest, its target the linearised output there in the calibrated scale, u s0
    (log["rate_unc_dps"] is u, linearised, at the scale the run had; the stage folds
    SF's constant s0 into rate.scale_dps), the bias as the pickoff delivers it: the
    firmware scales it by the compensation's scale factor (board_therm.h). Returns
    (values with the fusion on, its figures)."""
    rest = np.abs(log["rate_true_dps"]) < 1e-9  # (not calibrated yet: never valid here)
    u = np.asarray(log["rate_unc_dps"]) * s0
    try:
        model = boardcal.fit(log["t_s"], log["board_c"], u, rest)
    except InputError as e:
        raise FlowError(f"board thermometer: {e} ({cmd})") from None
    sf, b_s = compstudy.static_parts(log, v, v["rate.comp_tau_s"], v["rate.comp_stages"])
    parting = boardcal.parting_dps(log["t_s"], log["board_c"], b_s, model, sf)
    out = dict(v, **boardcal.values(model, parting))
    return out, dict(boardcal.doc(model), start_s=out["board.start_s"],
                     crossover_s=out["board.crossover_s"], parting_dps=parting,
                     agree_dps=out["board.agree_dps"])


def p_rate_turn(log):
    """The mean P_f against the table's rate over its held windows, a parabola: its slope
    (deg per deg/s) and curvature (deg per (deg/s)^2): the drive phase the rate itself
    turns (the reciprocal Coriolis force of the quadrature's sense motion, linear in the
    rate, and of the rate's own, with its square)."""
    win = scalefactor.windows_from_truth(log["t_s"], log["rate_true_dps"], SETTLE_S, MIN_AVG_S)
    segs = scalefactor.segment_means(log["t_s"], log["rate_dps"], win, p_deg=log["p_f_deg"])
    r = np.array([s.rate_in_dps for s in segs])
    p = np.array([s.mean_p_deg for s in segs])
    if r.size < 4 or np.ptp(r) <= 0.0:
        raise FlowError("rate table: too few held rates to measure P against the rate")
    c2, c1, _ = np.polyfit(r, p, 2)
    return float(c1), float(c2)


def _status_value(reply, key):
    """The value of `- KEY VALUE` in a status reply, or None."""
    for ln in (reply or "").splitlines():
        f = ln.split()
        if len(f) >= 3 and f[0] == "-" and f[1] == key:
            return f[2]
    return None


def selftest(part, values, lock_s=0.0):
    """Stage 3: the self-test expectations, measured on the calibrated part at rest. The
    commands wait for the drive's lock (lock_s, as the rate table measured it: the fixed
    drive on a Q 3000 part locks after about 3 s, and a self-test asked at 1 s was refused:
    'response 0 deg/s'); unchanged where it locks within half a second. Force rebalance
    has no on-demand test (its force would go past the loop, onto the loop's electrodes)
    and judges the continuous one against the loop model (gyro_design.c), nothing to
    calibrate: the stage checks that the part answers the model (selftest_fr)."""
    path = os.path.join(part.work, "selftest_params.json")
    paramset.write(path, paramset.from_values(values, meta={"stage": "self-test"}))
    lead = float(np.ceil(lock_s)) if lock_s > 0.5 else 0.0
    if force_rebalance(values):
        return selftest_fr(part, path, values, lead)
    scen = _scenario(part, "calibrate_selftest", {
        "description": "the self-test's responses on the calibrated part at rest",
        "duration_s": 6.0 + lead, "commands": [
            [1.0 + lead, "selftest"], [2.0 + lead, "status"],
            [2.1 + lead, "set selftest.cont_expect_dps 1 selftest.continuous 1"],
            [5.9 + lead, "status"]]})
    _, replies, cmd = _sim(part, path, scen, part.seed, "self-test")
    on_demand = _status_value(replies[1] if len(replies) > 1 else None, "selftest_dps")
    cont = _status_value(replies[3] if len(replies) > 3 else None, "selftest_cont_dps")
    if on_demand is None or cont is None:
        raise FlowError(f"self-test: no response in the status replies ({cmd})")
    on_demand, cont = float(on_demand), float(cont)
    if not (abs(on_demand) >= SELFTEST_MIN_DPS and cont >= SELFTEST_MIN_DPS):
        raise FlowError(f"self-test: response {on_demand:.3g} deg/s on demand, {cont:.3g} "
                        f"continuous, below {SELFTEST_MIN_DPS:g}: the self-test electrodes do "
                        "not act on this part")
    v = dict(values)
    v["selftest.expect_dps"] = on_demand
    v["selftest.cont_expect_dps"] = cont
    v["selftest.ref_amp_v"] = v["drive.amp_set_v"]
    return v, {"command": cmd, "expect_dps": on_demand, "cont_expect_dps": cont}


def cont_verdict(reply, tol_rel):
    """The continuous self-test in a status reply against its expectation: (response,
    expectation, within selftest.tol_rel of it), (None, None, False) when not shown."""
    got = _status_value(reply, "selftest_cont_dps")
    want = _status_value(reply, "selftest_cont_expect_dps")
    if got is None or want is None:
        return None, None, False
    got, want = float(got), float(want)
    return got, want, bool(want > 0.0 and abs(got - want) <= tol_rel * want)


def selftest_fr(part, path, values, lead):
    """Stage 3 in force rebalance: the continuous test's response on the calibrated part
    at rest against the loop model's expectation (the firmware's own, `status`), within
    the verdict's band; the set is unchanged."""
    scen = _scenario(part, "calibrate_selftest", {
        "description": "force rebalance's continuous self-test on the calibrated part at rest",
        "duration_s": 4.0 + lead, "commands": [[3.9 + lead, "status"]]})
    _, replies, cmd = _sim(part, path, scen, part.seed, "self-test")
    tol = values.get("selftest.tol_rel", 0.1)
    cont, model, ok = cont_verdict(replies[-1] if replies else None, tol)
    if cont is None:
        raise FlowError(f"self-test: no continuous response in the status reply ({cmd})")
    if not ok:
        raise FlowError(f"self-test: force rebalance's continuous response {cont:.4g} deg/s "
                        f"against the loop model's {model:.4g}, beyond +-{100 * tol:g} %: the "
                        "loop or its identified model is not the part's")
    v, figs = dict(values), {"command": cmd, "expect_dps": None, "cont_expect_dps": model,
                             "cont_dps": cont, "cont_model": True}
    if int(values.get("sense.tune", 0)) != 0:
        v["sense.tune_disc_zero_hz"] = disc_zero(replies[-1], values, cmd)
        figs["tune_disc_zero_hz"] = v["sense.tune_disc_zero_hz"]
    return v, figs


def disc_zero(reply, values, cmd):
    """The lost-match monitor's zero (sense.tune_disc_zero_hz): its reading on the tuned
    part at rest (`status` tune_detune_hz, taken from the zero the run had), where the
    sweep has just put the sense resonance on its target; the monitor's loop model alone
    reads a matched part 0.7-1.35 Hz off (firmware/gyro/sense_tune.h)."""
    got, match = _status_value(reply, "tune_detune_hz"), _status_value(reply, "tune_match")
    if got is None or match in (None, "0"):
        raise FlowError(f"self-test: the lost-match monitor gave no reading ({cmd})")
    zero = values.get("sense.tune_disc_zero_hz", 0.0) + float(got)
    if not abs(zero) <= DISC_ZERO_MAX_HZ:
        raise FlowError(f"self-test: the lost-match monitor reads {zero:+.3f} Hz on the tuned "
                        f"part, beyond +-{DISC_ZERO_MAX_HZ:g} Hz: the tuning or the loop's model "
                        f"is not the part's ({cmd})")
    return zero


def part_id(sets):
    """A stable id of the simulated part: CRC-32 of its settings (not of the noise)."""
    return zlib.crc32(("\n".join(sorted(sets)) + "\n").encode())


def wrap_deg(a):
    """An angle in degrees within [-180, 180)."""
    return (a + 180.0) % 360.0 - 180.0


def tune_volts(v):
    """The mode tuning's voltage at its own reference (firmware/gyro/sense_tune.h), V: what
    cal.ref_tune_v records, so that another tuning makes the calibration stale. 0 untuned
    (sense.tune 0) or not calibrated; the electrodes' limit when the target needs more."""
    mode = int(v.get("sense.tune", 0))
    s0, ref = v.get("sense.cal_s0_hz", 0.0), v.get("sense.cal_tune_ref_hz", 0.0)
    ke = v.get("sense.cal_tune_ke_per_s2_per_v2", 0.0)
    if mode == 0 or not (s0 > 0 and ref > 0 and ke > 0):
        return 0.0
    target = ref + (v.get("sense.tune_split_hz", 0.0) if mode == 2 else 0.0)
    v2 = ((2 * math.pi * s0) ** 2 - (2 * math.pi * target) ** 2) / ke
    return min(math.sqrt(v2), v.get("sense.tune_v_max_v", 10.0)) if v2 > 0 else 0.0


def record(values, sets, date=None, part_no=None):
    """Stage 3: the calibration record on top of the identified values; the part's id is
    part_no (a board's serial) or, for a simulated part, part_id of its settings."""
    v = dict(values)
    v["cal.ref_freq_hz"] = v["drive.freq_hz"]
    v["cal.ref_phase_set_deg"] = v["drive.phase_set_deg"]
    v["cal.ref_track"] = v["drive.track"]  # the mode the sweep chose and the stages ran in
    v["cal.ref_tune_v"] = tune_volts(v)  # the tuning the stages ran with
    # the sense configuration the stages ran in (force rebalance, nulling)
    v["cal.ref_sense_mode"] = v.get("sense.mode", 0)
    v["cal.ref_quad_null"] = v.get("quad.null", 0)
    v["cal.part_id"] = part_id(sets) if part_no is None else part_no
    d = date or datetime.date.today()
    v["cal.date"] = d.year * 10000 + d.month * 100 + d.day
    return v


def startup_lead_s(cal_path):
    """Rest before a verification's schedule, for the part's start-up: its rate is valid
    only after RATE_REF_WIDE_TAUS drive time constants (2Q/wn, rate_channel.h: the rate
    reference's wide start), 28 s at Q 3.3e4. 0 where the schedule's own first rest
    (2 s, then VERIFY_REST_S) covers it, as on the air parts (0.03 s): their schedule is
    unchanged. (Before, a Q 3e4 part's first dwells fell in its start-up and its valid
    fraction in the dwells, 87 %, failed the verification.)"""
    v = paramset.read(cal_path).values()
    tau = 2.0 * v["drive.cal_q"] / (2.0 * np.pi * v["drive.cal_f0_hz"])
    need = START_TAUS * tau + START_MARGIN_S - (2.0 + VERIFY_REST_S)
    return float(np.ceil(need)) if need > 0.0 else 0.0


def dwell_mask(t, truth, t_selftest, lead_s):
    """Where the verification judges the rate: the table's held windows (rests included)
    past SETTLE_S, before the self-test. After a start-up lead, the first held window (the
    lead and the schedule's first rests, all at 0) is the part's start-up, not a dwell:
    judged, it failed four Q 3e4 parts of the vacuum lot on their valid fraction (88 %)."""
    win = scalefactor.windows_from_truth(t, truth, SETTLE_S, MIN_AVG_S)
    m = np.zeros(t.size, dtype=bool)
    for _, i0, i1 in win:
        m[i0:i1] = True
    m &= t < t_selftest
    if lead_s > 0.0:
        m &= t >= lead_s + 2.0 + VERIFY_REST_S
    return m


def verify(part, cal_path):
    """Stage 4: the calibrated part on a profile and noise the fit never saw."""
    seed = part.seed + VERIFY_SEED_OFFSET
    lead = startup_lead_s(cal_path)
    steps = ([[lead, 0]] if lead > 0.0 else []) + lincal.table_steps(
        VERIFY_RATES_DPS, VERIFY_DWELL_S, VERIFY_REST_S) + [[2.5, 0]]
    duration = sum(st[0] for st in steps)
    # The on-demand self-test in the last 1.2 s, at rest; the rate is judged before it.
    # Force rebalance has none: its continuous test, against the loop model, at the end.
    t_selftest = duration - 1.2
    cal = paramset.read(cal_path).values()
    fr = force_rebalance(cal)
    scen = _scenario(part, "calibrate_verify", {
        "description": "verification of a calibration: rates and dwell the fit never saw",
        "duration_s": duration, "csv_rate_hz": 200,
        "rate_dps": {"kind": "steps", "edge_s": 0.1, "steps": steps},
        "commands": ([] if fr else [[t_selftest, "selftest"]]) + [[duration - 0.05, "status"]]})
    log, replies, cmd = _sim(part, cal_path, scen, seed, "verify", csv=True)
    st_state = _status_value(replies[-1] if replies else None, "selftest")
    if fr:
        ok = cont_verdict(replies[-1] if replies else None, cal.get("selftest.tol_rel", 0.1))[2]
        st_state = "continuous PASS" if ok else "continuous FAIL"
    t, out, truth = log["t_s"], log["rate_dps"], log["rate_true_dps"]
    valid = log["rate_valid"] > 0.5
    res = scalefactor.analyse(t, out, rate_true_dps=truth, settle_s=SETTLE_S,
                              min_avg_s=MIN_AVG_S)
    in_dwell = dwell_mask(t, truth, t_selftest, lead)
    err = np.abs(out - truth)
    valid_frac = float(np.mean(valid[in_dwell])) if np.any(in_dwell) else 0.0
    # Judged where the input is held (after SETTLE_S): during a table's ramp the 100 Hz
    # output lags the input by its group delay, which is the output's bandwidth, not an
    # error of its calibration.
    judged = valid & in_dwell
    worst = float(np.max(err[judged])) if np.any(judged) else 0.0
    rest = in_dwell & valid & (np.abs(truth) < 1e-9)
    bias = float(np.mean(out[rest])) if np.any(rest) else float("nan")
    # The scale factor is the slope over the thesis's table (+-20..160 deg/s); every
    # sub-range's against it.
    # The held means from where the drive stays LOCKED (the fixed drive at Q 3000 locks
    # after about 3 s; before, the output is the acquisition's: a scale factor of
    # -5e10 ppm was read so).
    r_h, m_h, se_h = _held_means(locked_log(log, "verify"), "rate_dps", t_end_s=t_selftest)
    m_h = m_h - np.where(r_h != 0.0, lincal.bias_between_rests(r_h, m_h), 0.0)
    turning = np.abs(r_h) > 0.0  # the rests are the bias's (and the self-test's)
    sub, sf = lincal.subrange_slopes(r_h[turning], m_h[turning], se_h[turning])
    sf_ppm = (sf - 1.0) * 1e6
    worst_sub = sub[0] if sub else None
    checks = {
        "scale_factor": abs(sf_ppm) <= VERIFY_SF_PPM,
        "subrange_slopes": worst_sub is not None and
        abs(worst_sub["slope_ppm"]) <= lincal.SUBRANGE_PPM,
        "bias_at_rest": bool(np.isfinite(bias) and abs(bias) <= VERIFY_BIAS_DPS),
        "valid_fraction": valid_frac >= VERIFY_VALID_FRAC,
        "no_valid_wrong_rate": worst <= VERIFY_MAX_ERR_DPS,
        "selftest": st_state in ("PASS", "continuous PASS"),
    }
    return {"command": cmd, "seed": seed, "rates_dps": list(VERIFY_RATES_DPS),
            "dwell_s": VERIFY_DWELL_S, "lead_s": lead, "scale_factor": sf, "scale_factor_ppm": sf_ppm,
            "scale_factor_all_rates": res.sf, "nonlinearity_fs": res.nonlinearity,
            "subrange_min_span_dps": lincal.SUBRANGE_MIN_DPS, "subrange_worst": worst_sub,
            "subrange_slopes": sub, "bias_at_rest_dps": bias,
            "valid_fraction_in_dwell": valid_frac, "worst_valid_error_dps": worst,
            "invalid_s_by_reason": fields.invalid_time_s(t, log["rate_invalid"]),
            "selftest": st_state,
            "limits": {"scale_factor_ppm": VERIFY_SF_PPM, "bias_dps": VERIFY_BIAS_DPS,
                       "subrange_slope_ppm": lincal.SUBRANGE_PPM,
                       "valid_fraction": VERIFY_VALID_FRAC,
                       "worst_valid_error_dps": VERIFY_MAX_ERR_DPS},
            "checks": checks, "passed": all(checks.values())}


def powered(part, cal_path):
    """The set the simulator's warm runs verify: every run but the cold start begins with
    the part's thermal network in its steady state, the board's own dissipation in it, as
    a part powered for long, whose firmware handed over to the board thermometer long
    since (board.start_s, then board.fade_s, after power-on, board_therm.h); its uptime
    starts at 0 in the run, so those runs set both 0. The cold start runs the set as
    written. On a
    port, or without the fusion, the set itself."""
    vals = paramset.read(cal_path).values()
    if part.port is not None or int(vals.get("board.fuse", 0)) != 1:
        return cal_path
    path = os.path.join(part.work, "calibration_powered.json")
    paramset.write(path, paramset.from_values(dict(vals, **{"board.start_s": 0.0,
                                                             "board.fade_s": 0.0}), meta={
        "stage": "verify: the calibration as a part powered for long runs it"}))
    return path


def _thermal_runs(part, cal_path, warm):
    """The thermal verification's runs, as (name, function of nothing -> figures); warm
    the set the warm runs take (powered)."""
    seed = part.seed + VERIFY_SEED_OFFSET
    proto = part.protocol
    temps = proto.verify_plateaus_c

    def run(name, doc, k, judge):
        scen = _scenario(part, "calibrate_" + name, doc)
        log, _, cmd = _sim(part, cal_path if name == "verify_warmup" else warm, scen, seed + k,
                           name, csv=True, columns=THERMAL_COLUMNS)
        return dict(judge(log), command=cmd, seed=seed + k,
                    invalid_s_by_reason=fields.invalid_time_s(log["t_s"], log["rate_invalid"]))

    def judge_plateaus(log):
        rows = thermcal.verify_plateaus(log, temps, proto.dwell_s)
        return {"plateaus": rows, "ok": all(r["ok"] for r in rows)}

    return [
        ("thermal_plateaus", lambda: run("verify_plateaus", thermcal.plateau_scenario(
            temps, proto.dwell_s,
            {"description": "verification of a thermal calibration: plateaus it never saw"}),
            1, judge_plateaus)),
        ("thermal_ramp", lambda: run("verify_ramp", thermcal.ramp_scenario(
            {"description": "verification of a thermal calibration: a heating ramp"}, proto),
            2, lambda log: thermcal.verify_ramp(log, proto))),
        ("noise", lambda: run("verify_noise", thermcal.noise_scenario(
            {"description": "output noise with and without the temperature compensation"},
            proto), 3, lambda log: thermcal.verify_noise(log, proto))),
        ("thermal_transient", lambda: run("verify_transient", thermcal.transient_scenario(
            {"description": "verification of a thermal calibration: a fast transient (heat "
                            "gun, then the room)"}, proto),
            4, lambda log: thermcal.verify_transient(log, proto))),
        ("warmup", lambda: run("verify_warmup", thermcal.warmup_scenario(
            {"description": "verification of a thermal calibration: a cold start at rest "
                            "(IEEE 1431 12.6 warm-up time)"}, proto),
            5, lambda log: thermcal.verify_warmup(log, proto))),
    ]


def verify_all(part, cal_path, workers=None):
    """Every verification run side by side (one gyro-sim process each): a dict of their
    figures, each with "ok" or "passed"."""
    warm = powered(part, cal_path)
    jobs = [("rate", lambda: verify(part, warm))] + _thermal_runs(part, cal_path, warm)
    n = 1 if part.port is not None else workers or os.cpu_count() or 1  # one part, one bench
    with concurrent.futures.ThreadPoolExecutor(max_workers=n) as pool:
        futs = {name: pool.submit(fn) for name, fn in jobs}
        return {name: f.result() for name, f in futs.items()}


def verify_passed(res):
    return all(v.get("passed", v.get("ok", False)) for v in res.values())


def check_sets(sets):
    for s in sets:
        key = s.split("=", 1)[0]
        if "=" not in s or not key.startswith("plant."):
            raise InputError(f"--set {s}: only plant.KEY=V chooses the part (the firmware's "
                             "values are what the flow finds; its sense configuration is "
                             "--sense, --fb-scheme, --quad-null and --tune)")
