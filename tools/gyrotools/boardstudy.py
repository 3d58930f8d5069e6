"""Three thermometers for the temperature compensation: the drive phase P, a board
temperature sensor, and a model-based fusion of both (tools/board_thermometer_study,
docs/compensation-noise.md, "Thermal couplings, board sensor, fusion").

An offline study: the firmware has no board-temperature input. For each thermometer the
compensation is refitted on the calibration run's log exactly as the flow fits P
(thermcal.fit with the full protocol's filter: three first-order stages of 15 s, the 5 s
fast path and its blend, the gradient term's time constant from thermcal.TAU_GRID_S, the
output linearised first as calflow.thermal does), with the thermometer's reading in place
of P_f, and applied as the firmware would (compstudy.compensate) to the verification logs
the fit never saw. The judgements are the flow's own (thermcal.verify_ramp,
verify_transient, verify_plateaus; the noise ratio as thermcal.verify_noise forms it,
read at 1, 10, 100 and 1000 s on a long run at 25 degC). The rate_valid column of each log
is the firmware's (its P-based monitors) for all three thermometers.

The board sensor (BoardSensor, sensor_reading): a TI TMP117 on the board's I2C bus, read
by the simulator's board node t_board_c. Chosen over an ADT7420-class part (16 bit,
0.0078 degC as well, but +-0.25 degC and no averaging) for its accuracy and its
on-chip averaging. Datasheet facts (TI SNOSD82D, "TMP117 High-Accuracy, Low-Power,
Digital Temperature Sensor With SMBus- and I2C-Compatible Interface", June 2018, revised
September 2022): 16-bit result, 1 LSB = 7.8125 mdegC (7.3.3); accuracy +-0.1 degC from
-20 to 50 degC, +-0.15 degC from -40 to 70 degC, +-0.2 degC from -40 to 100 degC (1); one
conversion takes 15.5 ms and the result of AVG = 8 is the mean of eight (124 ms); the
repeatability is about +-3 LSB without averaging and +-1 LSB with eight averages
(7.3.2, the noise histograms); the factory setting is eight averages every 1 s. The model:
a conversion every `cycle_s` (1 s) at a phase drawn from the seed, the mean of the board
node over its 124 ms of active conversion, plus the accuracy error (an offset within
+-0.1 degC and a slope error that keeps it within +-0.2 degC over -40..85 degC, drawn from
the seed: a smooth error of the reading, which the fit's cubic in the reading takes out as
it takes out any thermometer's offset and scale), plus the repeatability as Gaussian noise
(+-3 LSB read as +-2 sigma: 1.5 LSB per conversion, 1.5 / sqrt(8) = 0.53 LSB averaged),
rounded to 1 LSB and held until the next conversion. The sensor's self-heating and its
long-term drift are not modelled (3.5 uA at 1 Hz; the drift is over months, the runs
hours).

The fusions (fit_board_model, fused_thermometer): the board reading through a transfer
fitted on the calibration log, for the slow part, and P for the fast. In a thermal network
of lumped nodes driven by one input (the surroundings; host_sim/plant/thermal.h) every
node is a rational transfer of that input with the network's poles, so any node's
temperature, and any linear mix of them, is the board's through N(s) / N_b(s): two zeros
over two poles for three nodes, whatever the couplings. The model is that transfer, of
unit DC gain, (1 + s z1)(1 + s z2) / ((1 + s p1)(1 + s p2)), followed by a cubic in its
output (a Wiener model: the cubic takes the target's curvature in temperature, the
board's self-heating offset and the sensor's accuracy error); its four time constants
and the cubic are fitted by least squares to the target's 1 s means at rest on the
calibration log (scipy least_squares on the time constants, the cubic linear within).
Two targets:
- "fusion_p": P_f. The fused thermometer is P - LP_T(P - M(board)), P less the
  low-passed disagreement between P and the board's model of it, in P's units;
- "fusion_bias": the linearised output at rest, i.e. the bias itself, which weighs the
  structure and the circuit as the part does (P reads the structure only). P enters as the
  bias its own compensation's cubic reads (p_as_bias, the P fit's values), and the fused
  thermometer, in deg/s, is P_b - LP_T(P_b - M(board)).
Either is then a thermometer like P: the flow's fit (cubic, gradient term, filters, fast
path) is made on it. Above 1 / (2 pi T) it is P's, below the model's (the steady-state
Kalman filter of a model error that wanders as a random walk under white measurement
noise has this form), so the drive pickoff's phase flicker (1/f, the 1.9x at 100..1000 s)
is replaced by the sensor's noise through the model at long times, while a change the
model misses is still read by P within T. T (`crossover_s`, CROSSOVER_S) is the one free
choice. The model assumes the surroundings are the only heat input that changes: after a
power-on the board's own dissipation is a second one: the study then takes the output of
P's own compensation for FUSION_COLD_START_S and hands over to the fusion's over
FUSION_FADE_S (handed_over), as a firmware running both would.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy import optimize, signal

from . import compstudy, lincal, tempcomp, thermcal

TAUS_S = compstudy.TAUS_S
FUSIONS = ("fusion_p", "fusion_bias")
THERMOMETERS = ("P", "board") + FUSIONS
# The fused thermometer's crossover (s). The drive pickoff's phase flicker is in excess
# from 10 s on (1.09x there with the flow's three 15 s stages, 1.9x at 100..1000 s); to
# keep it out of every band from 10 s up the crossover lies well below: 3 s, 53 mHz. P's
# share is then what changes faster than the model follows, which the compensation's own
# filters (15 s stages, the 5 s fast path) mostly take out: at this crossover the fused
# thermometer is nearly the board's model of P, and an error of the model slower than a
# few seconds is not corrected by P (tools/board_thermometer_study --scan shows the trade).
CROSSOVER_S = 3.0
# After a cold start the board's own dissipation warms it for minutes (a second heat input
# the model, fitted on a chamber run that starts warm, does not have): the output is P's
# own compensation's for this long after power-on, five of the default network's slowest
# thermal mode (306 s, tools/thermal_warmup.py), then hands over to the fusion's.
FUSION_COLD_START_S = 1500.0
FUSION_FADE_S = 300.0
# The model's fit starts after the calibration log's first plateau has had this long (the
# run starts in the steady state of 25 degC, the model's filter at the first reading).
MODEL_START_S = 120.0


@dataclasses.dataclass(frozen=True)
class BoardSensor:
    """A TMP117 (TI SNOSD82D) as the study reads it (module doc)."""
    lsb_c: float = 0.0078125          # 7.3.3
    averages: int = 8                  # AVG = 01 (factory setting)
    conversion_s: float = 0.0155       # one active conversion, 7.3.2
    cycle_s: float = 1.0               # conversion cycle (factory setting: 1 s)
    sigma_single_lsb: float = 1.5      # repeatability +-3 LSB, read as +-2 sigma
    offset_max_c: float = 0.1          # accuracy, -20..50 degC
    accuracy_max_c: float = 0.2        # accuracy, -40..100 degC
    span_c: tuple = (-40.0, 85.0)      # the product's temperature range

    @property
    def sigma_c(self):
        """The repeatability of one averaged result (degC, before rounding)."""
        return self.sigma_single_lsb * self.lsb_c / np.sqrt(self.averages)


TMP117 = BoardSensor()


def accuracy_error(sensor, seed):
    """(offset degC, slope degC/degC about 25 degC) of one sensor, drawn from the seed
    within the datasheet's accuracy: the offset within offset_max_c, the slope so that
    offset + slope (T - 25) stays within accuracy_max_c over span_c."""
    rng = np.random.default_rng([seed, 1])
    off = rng.uniform(-sensor.offset_max_c, sensor.offset_max_c)
    reach = max(abs(s - 25.0) for s in sensor.span_c)
    slope = rng.uniform(-1.0, 1.0) * (sensor.accuracy_max_c - abs(off)) / reach
    return float(off), float(slope)


def sensor_reading(t_s, t_board_c, sensor=TMP117, seed=0, part_seed=0):
    """The sensor's reading at each of a log's rows (degC): its last finished conversion
    (module doc); the conversions' phase and noise drawn from seed, the part's accuracy
    error from part_seed (one sensor, many runs). The node is smooth, so the mean over a
    conversion's active time is the node's value at its middle."""
    t = np.asarray(t_s, dtype=float)
    tb = np.asarray(t_board_c, dtype=float)
    rng = np.random.default_rng([seed, 0])
    phase = rng.uniform(0.0, sensor.cycle_s)
    t_conv = np.arange(t[0] + phase, t[-1] + sensor.cycle_s, sensor.cycle_s)
    active = sensor.averages * sensor.conversion_s
    true = np.interp(t_conv - 0.5 * active, t, tb)
    off, slope = accuracy_error(sensor, part_seed)
    raw = true + off + slope * (true - 25.0) + sensor.sigma_c * rng.standard_normal(t_conv.size)
    code = np.round(raw / sensor.lsb_c) * sensor.lsb_c
    k = np.searchsorted(t_conv, t, side="right") - 1
    return code[np.maximum(k, 0)]


def _lead_lag(tc_s, dt_s):
    """(b, a) of (1 + s z1)(1 + s z2) / ((1 + s p1)(1 + s p2)) at dt_s (Tustin);
    tc_s = (z1, z2, p1, p2) in seconds."""
    z1, z2, p1, p2 = tc_s
    num = np.polymul([z1, 1.0], [z2, 1.0])
    den = np.polymul([p1, 1.0], [p2, 1.0])
    b, a, _ = signal.cont2discrete((num, den), dt_s, method="bilinear")
    return np.ravel(b), np.ravel(a)


def lead_lag(t_s, x, tc_s):
    """x through the unit-DC-gain lead-lag of tc_s, starting in its steady state."""
    t = np.asarray(t_s, dtype=float)
    x = np.asarray(x, dtype=float)
    b, a = _lead_lag(tc_s, float(np.median(np.diff(t))))
    y, _ = signal.lfilter(b, a, x, zi=signal.lfilter_zi(b, a) * x[0])
    return y


@dataclasses.dataclass
class BoardModel:
    """The board reading's model of a target (P, or the bias): the lead-lag tc_s, then
    the cubic c (in the lead-lag's output less ref_c); rms its residual on the fit's 1 s
    means, in the target's unit."""
    tc_s: tuple
    c: np.ndarray
    ref_c: float
    rms: float

    def __call__(self, t_s, board_c):
        return tempcomp.poly_eval(self.c, lead_lag(t_s, board_c, self.tc_s) - self.ref_c)


def _bins(t, cols):
    return tempcomp.bin_average(t, cols, thermcal.BIN_S)


def fit_board_model(t_s, board_c, target, rest, start_s=MODEL_START_S,
                    guess_s=(300.0, 30.0, 600.0, 60.0)):
    """The board reading's model of target (module doc), fitted on 1 s means: the
    lead-lag runs over every bin, the residual is taken over the bins at rest after
    start_s."""
    t = np.asarray(t_s, dtype=float)
    b = _bins(t, {"b": np.asarray(board_c, float), "p": np.asarray(target, float),
                  "r": np.asarray(rest, float)})
    use = (b["r"] > 0.999) & (b["t_s"] >= start_s)
    ref = float(np.mean(b["b"][use]))

    def cubic(tc):
        u = lead_lag(b["t_s"], b["b"], tc)[use] - ref
        a = np.column_stack([np.ones_like(u), u, u * u, u ** 3])
        c, *_ = np.linalg.lstsq(a, b["p"][use], rcond=None)
        return c, b["p"][use] - a @ c

    res = optimize.least_squares(lambda q: cubic(np.exp(q))[1], np.log(guess_s),
                                 bounds=(np.log(1.0), np.log(1e5)), x_scale=1.0)
    tc = tuple(float(v) for v in np.exp(res.x))
    c, r = cubic(tc)
    return BoardModel(tc, c, ref, float(np.sqrt(np.mean(r ** 2))))


def fused_thermometer(t_s, p_deg, board_c, model, crossover_s=CROSSOVER_S):
    """P - LP_T(P - M(board)): P above the crossover, the board's model of it below. The
    low-pass starts at thermcal.START_S (as the firmware's thermometer filters do) at the
    disagreement of that moment."""
    t = np.asarray(t_s, dtype=float)
    p = np.asarray(p_deg, dtype=float)
    return p - thermcal.comp_thermometer(t, p - model(t, board_c), crossover_s, 1)


def handed_over(t_s, out_p, out_fused, start_s=None, fade_s=None):
    """After a power-on: the output of P's own compensation until start_s
    (FUSION_COLD_START_S), then a linear hand-over to the fusion's output over fade_s
    (FUSION_FADE_S), so that what the two still disagree by then is not a step."""
    start_s = FUSION_COLD_START_S if start_s is None else start_s
    fade_s = FUSION_FADE_S if fade_s is None else fade_s
    w = np.clip((np.asarray(t_s, dtype=float) - start_s) / fade_s, 0.0, 1.0)
    return (1.0 - w) * np.asarray(out_p) + w * np.asarray(out_fused)


# The verification logs a study reads (the flow's work folder) and the columns it needs.
VERIFY_LOGS = ("verify_plateaus", "verify_ramp", "verify_transient")
COLUMNS = ("rate_true_dps", "rate_valid", "rate_unc_dps", "p_f_deg", "t_struct_c", "t_board_c")
# The sensor's noise seed of each log: its own, as each verification run has its own.
SENSOR_SEEDS = {"thermal": 11, "verify_plateaus": 12, "verify_ramp": 13,
                "verify_transient": 14, "noise": 15, "warmup": 16, "noise_long": 17}
# The noise ratio at this tau and beyond is read on the long run ("noise_long") when there
# is one: the flow's 1200 s run holds 100 s on a dozen windows and 1000 s not at all.
LONG_TAU_S = 100.0


def linearised(log, values):
    """The uncompensated output as the compensation sees it: L(u) (calflow.thermal)."""
    return lincal.linearise(log["rate_unc_dps"], values.get("rate.lin_c2_per_dps", 0.0),
                            values.get("rate.lin_c3_per_dps2", 0.0))


def view(log, thermometer, u):
    """A log as thermcal reads it, with the thermometer's reading as p_f_deg and the
    linearised output as rate_unc_dps."""
    d = compstudy._View({n: np.asarray(log[n]) for n in ("t_s", "rate_true_dps", "rate_valid",
                                                          "t_struct_c")})
    d["p_f_deg"] = np.asarray(thermometer, dtype=float)
    d["rate_unc_dps"] = np.asarray(u, dtype=float)
    return d


def fit(cal_view, proto=thermcal.FULL):
    """The compensation for a thermometer, fitted as the flow fits P (thermcal.fit with
    the protocol's filters and fast path): (values, figures)."""
    v, _, figs = thermcal.fit(cal_view, proto.cal_plateaus_c, proto.dwell_s,
                              proto.span_from_data, comp_tau_s=proto.comp_tau_s,
                              comp_stages=proto.comp_stages,
                              comp_fast_tau_s=proto.comp_fast_tau_s)
    return v, figs


def compensated(lview, v, proto=thermcal.FULL):
    """The firmware's output on a log view for the values v."""
    out = view(lview, lview["p_f_deg"], lview["rate_unc_dps"])
    out["rate_dps"] = compstudy.compensate(lview, v, proto.comp_tau_s, proto.comp_stages)
    return out


def noise_ratio(lview, v, proto=thermcal.FULL, taus=TAUS_S):
    """Allan deviation of the compensated output against the uncompensated (both
    linearised, as the firmware's) at taus, the first START_S left out: (ratios,
    compensated deg/h, uncompensated deg/h); nan beyond what the record holds."""
    t = lview["t_s"]
    m = t >= thermcal.START_S
    fs = 1.0 / float(np.median(np.diff(t)))
    a_c = compstudy.adev_at(compstudy.compensate(lview, v, proto.comp_tau_s,
                                                 proto.comp_stages)[m], fs, taus)
    a_u = compstudy.adev_at(np.asarray(lview["rate_unc_dps"])[m], fs, taus)
    return [c / u for c, u in zip(a_c, a_u)], a_c, a_u


def judge(views, v, proto=thermcal.FULL):
    """The flow's verdicts for the values v on the verification views (plateaus, ramp,
    transient, and noise when present)."""
    pl = thermcal.verify_plateaus(compensated(views["verify_plateaus"], v, proto),
                                  proto.verify_plateaus_c, proto.dwell_s)
    ramp = thermcal.verify_ramp(compensated(views["verify_ramp"], v, proto), proto)
    tr = thermcal.verify_transient(compensated(views["verify_transient"], v, proto), proto)
    worst = max(pl, key=lambda r: abs(r["bias_dps"]))
    res = {"plateau_bias_dps": [r["bias_dps"] for r in pl],
           "plateau_worst_dps": worst["bias_dps"], "plateau_worst_c": worst["ambient_c"],
           "plateaus_ok": all(r["ok"] for r in pl),
           "ramp_std_dps": ramp["bias_1s_std_dps"], "ramp_max_dps": ramp["bias_1s_max_abs_dps"],
           "ramp_ok": ramp["ok"], "transient_std_dps": tr["bias_1s_std_dps"],
           "transient_pp_dps": tr["bias_1s_pp_dps"], "transient_ok": tr["ok"]}
    if "noise" in views:
        # 1 and 10 s on the flow's own noise run (as it judges them), 100 and 1000 s on
        # the long run when there is one
        r, a_c, a_u = noise_ratio(views["noise"], v, proto)
        if "noise_long" in views:
            long = noise_ratio(views["noise_long"], v, proto)
            for k, tau in enumerate(TAUS_S):
                if tau >= LONG_TAU_S:
                    r[k], a_c[k], a_u[k] = long[0][k], long[1][k], long[2][k]
        lim = thermcal.LIMITS["noise_ratio"]
        res.update({"taus_s": list(TAUS_S), "noise_ratio": r, "adev_compensated_dph": a_c,
                    "adev_uncompensated_dph": a_u,
                    "noise_ok": bool(r[0] <= lim and r[1] <= lim)})
    return res


def board_readings(logs, sensor=TMP117, part_seed=1):
    """Per log name, the board sensor's reading (its noise seeded per log, SENSOR_SEEDS;
    its accuracy error per part)."""
    return {n: sensor_reading(lg["t_s"], lg["t_board_c"], sensor, SENSOR_SEEDS.get(n, 18),
                              part_seed) for n, lg in logs.items()}


def board_model(cal_log, board_c, target):
    """The board reading's model of target (P_f, or the linearised output: the bias) on
    the calibration log at rest (fit_board_model)."""
    t = cal_log["t_s"]
    rest = (np.abs(cal_log["rate_true_dps"]) < 1e-9) & (t >= thermcal.START_S)
    return fit_board_model(t, board_c, target, rest)


def p_as_bias(p_deg, v):
    """P through the P compensation's static cubic (values v): the bias P alone reads,
    deg/s; the fast part of the fusion with the board's model of the bias."""
    return compstudy._bias(v, np.asarray(p_deg, dtype=float) - v["cal.ref_p_deg"])


def fused_readings(logs, board, models, v_p, crossover_s):
    """Per fusion (FUSIONS) and log name, the fused thermometer: P with the board's model
    of P ("fusion_p", deg), or P's bias with the board's model of the bias ("fusion_bias",
    deg/s)."""
    out = {}
    for name, model in models.items():
        out[name] = {}
        for n, lg in logs.items():
            p = lg["p_f_deg"] if name == "fusion_p" else p_as_bias(lg["p_f_deg"], v_p)
            out[name][n] = fused_thermometer(lg["t_s"], p, board[n], model, crossover_s)
    return out


def evaluate(logs, readings, values, proto=thermcal.FULL):
    """One thermometer: readings (log name -> its reading) in place of P_f, the
    compensation fitted on "thermal" as the flow fits P, the flow's verdicts on the
    others (and the cold start's when "warmup" is there)."""
    views = {n: view(lg, readings[n], linearised(lg, values)) for n, lg in logs.items()}
    v, figs = fit(views["thermal"], proto)
    r = judge(views, v, proto)
    if "warmup" in views:
        w = thermcal.verify_warmup(compensated(views["warmup"], v, proto), proto)
        r.update({"warmup_time_s": w["warmup_time_s"],
                  "warmup_worst_dps": w["worst_valid_1s_dps"], "warmup_ok": w["ok"]})
    r.update({"fit_rms_1s_dps": figs["fit_rms_1s_dps"], "grad_tau_s": v["rate.grad_tau_s"],
              "values": {k: v[k] for k in sorted(v)}})
    r["ok"] = bool(r["plateaus_ok"] and r["ramp_ok"] and r["transient_ok"]
                   and r.get("noise_ok", True))
    return r


def _model_doc(m):
    return {"tc_s": list(m.tc_s), "cubic": m.c.tolist(), "ref_c": m.ref_c, "rms": m.rms}


def _cold_start_held(logs, fused, res, values, proto):
    """The fusions on the cold start, handed over from P's compensation after power-on
    (handed_over)."""
    lg = logs["warmup"]
    u = linearised(lg, values)
    out_p = compensated(view(lg, lg["p_f_deg"], u), res["P"]["values"], proto)
    out = {}
    for name in FUSIONS:
        lv = compensated(view(lg, fused[name]["warmup"], u), res[name]["values"], proto)
        lv["rate_dps"] = handed_over(lg["t_s"], out_p["rate_dps"], lv["rate_dps"])
        w = thermcal.verify_warmup(lv, proto)
        out[name] = {"start_s": FUSION_COLD_START_S, "fade_s": FUSION_FADE_S,
                     "warmup_time_s": w["warmup_time_s"],
                     "warmup_worst_dps": w["worst_valid_1s_dps"], "warmup_ok": w["ok"]}
    return out


def study(logs, values, sensor=TMP117, part_seed=1, crossover_s=CROSSOVER_S,
          proto=thermcal.FULL, scan_s=()):
    """One part: logs (name -> columns: "thermal", the VERIFY_LOGS, "noise" (the flow's
    verify_noise), optionally "noise_long" and "warmup"), values (its lin coefficients).
    For each thermometer (THERMOMETERS) the fit on "thermal" and the flow's verdicts on
    the others; the fusions again for each crossover of scan_s, and held after power-on
    on the cold start. Returns {"models": ..., thermometer: results, "scan": [...],
    "cold_start_held": ...}."""
    board = board_readings(logs, sensor, part_seed)
    cal = logs["thermal"]
    res = {"crossover_s": crossover_s,
           "P": evaluate(logs, {n: lg["p_f_deg"] for n, lg in logs.items()}, values, proto),
           "board": evaluate(logs, board, values, proto)}
    models = {"fusion_p": board_model(cal, board["thermal"], cal["p_f_deg"]),
              "fusion_bias": board_model(cal, board["thermal"], linearised(cal, values))}
    res["models"] = {k: _model_doc(m) for k, m in models.items()}
    v_p = res["P"]["values"]
    fused = fused_readings(logs, board, models, v_p, crossover_s)
    for name in FUSIONS:
        res[name] = evaluate(logs, fused[name], values, proto)
    if "warmup" in logs:
        res["cold_start_held"] = _cold_start_held(logs, fused, res, values, proto)
    res["scan"] = []
    for x in scan_s:
        fused = fused_readings(logs, board, models, v_p, x)
        for name in FUSIONS:
            res["scan"].append(dict(evaluate(logs, fused[name], values, proto),
                                    crossover_s=x, fusion=name))
    return res
