"""A report of a calibration's verification shaped after IEEE Std 1431-2004 (Coriolis
vibratory gyros: the test procedures of clause 12), with IEEE Std 952's noise
coefficients; tools/calibrate writes it after the verification, into DIR/ieee1431/.

From DIR/report.json's "verify" section and the verification runs' logs in DIR/work/:

- turn_on.png (12.5 turn-on time), from verify.csv, which starts at power-on with the
  part at rest: the turn-on time is the time from power-on (t_s = 0) to the first sample
  after which rate_valid stays 1 until the input first moves (or the self-test starts);
  the time to the error bound is the time to the first sample after which
  |rate_dps - rate_true_dps| stays within the verification's bound (its worst valid
  error, 1 deg/s) over the same rest, whether the output is marked valid or not (this
  run starts at the part's own thermal equilibrium: the start's and the end's
  structure temperature are reported);
- warm_up.png (12.6 warm-up time), from verify_warmup.csv, a cold start at rest (every
  node of the thermal network at the ambient at power-on, the part's own dissipation
  warming it): thermcal.verify_warmup's figures, the time from power-on after which the
  1 s means of the valid output stay within the compensation's bound (0.2 deg/s), and
  the raw output's own settling to its final level, for comparison;
- scale_factor.png (12.9 scale factor test series), from verify.csv: the held rates'
  means, each rate against the rests around it (the verification's rate transfer test,
  lincal.bias_between_rests), valid samples only, before the self-test; scale factor,
  bias, nonlinearity and asymmetry by scalefactor.fit over the rates (+-30..270 deg/s;
  the rests' means, whose scatter is the bias's wander, reported apart);
- drift.png (12.11 drift rate test series), from verify_noise.csv: the 1 s means of
  rate_dps and rate_unc_dps from thermcal.START_S on, their Allan deviations
  (allan.analyse, as tools/gyro-allan) and the IEEE 952 coefficients N, B, K, R
  (allan.ieee952: null with the reason where the record does not show one);
- temperature.png (12.8 operating temperature test series), from verify_plateaus.csv
  and verify_ramp.csv: bias and scale factor at each verification plateau
  (thermcal.verify_plateaus) against the chamber's ambient and the structure's
  temperature, and the ramp's 1 s bias means (thermcal.rest_bins, the bins the
  verification judged) against both;
- ieee1431.json: every figure (units in the keys), each series' gyro-sim command and
  seed (from report.json), the PNGs' and logs' paths relative to DIR/ieee1431/; NaN is
  written as null (cli.write_json).

A log that is missing or unusable leaves its series out: the series' entry holds
"error" (the file and why) and write() returns the problems for the caller to say
aloud; the other series are still written. Only report.json itself, missing or not a
verification's, stops the report (InputError).
"""

from __future__ import annotations

import dataclasses
import json
import os

import numpy as np

from . import calflow, cli, csvlog, thermcal
from . import ieee1431_figures as figures
from .errors import InputError

FOLDER = "ieee1431"
# The columns each log must have, and those read when present.
NEED = {
    "verify.csv": ("rate_dps", "rate_true_dps", "rate_valid", "rate_invalid"),
    "verify_noise.csv": ("rate_dps", "rate_unc_dps"),
    "verify_plateaus.csv": ("rate_dps", "rate_true_dps", "rate_valid", "p_f_deg"),
    "verify_ramp.csv": ("rate_dps", "rate_true_dps", "rate_valid"),
    "verify_warmup.csv": ("rate_dps", "rate_unc_dps", "rate_true_dps", "rate_valid"),
}
WANT = figures.TEMPERATURES + ("t_circuit_c",)  # the circuit's: warm_up.png, when logged
FILES = ("turn_on.png", "warm_up.png", "scale_factor.png", "drift.png", "temperature.png",
         "ieee1431.json")


@dataclasses.dataclass
class Context:
    """What every series needs: the report, where the logs are, the part's name."""
    out: str            # DIR
    folder: str         # DIR/ieee1431
    report: dict
    protocol: thermcal.Protocol
    logs: dict = dataclasses.field(default_factory=dict)  # name -> Log or InputError

    @property
    def verify(self):
        return self.report["verify"]

    def sets(self):
        part = self.report.get("part")
        return list(part.get("set") or []) if isinstance(part, dict) else []

    def part(self):
        sets = self.sets()
        return "default part" if not sets else "part " + " ".join(sets)

    def log(self, name):
        """The log DIR/work/NAME with its NEED columns, read once; InputError (naming the
        file and why) when it is missing or unusable."""
        if name not in self.logs:
            path = os.path.join(self.out, "work", name)
            try:
                self.logs[name] = csvlog.read_log(path, need=NEED[name], want=WANT,
                                                  purpose=f"the IEEE 1431 report ({name})")
            except InputError as e:
                self.logs[name] = e
        got = self.logs[name]
        if isinstance(got, InputError):
            raise got
        return got

    def rel(self, path):
        return os.path.relpath(path, self.folder)


def load(out_dir):
    """The Context of DIR, from DIR/report.json (InputError when it is missing, not JSON
    or holds no verification)."""
    path = os.path.join(out_dir, "report.json")
    try:
        with open(path, encoding="utf-8") as fh:
            report = json.load(fh)
    except OSError as e:
        raise InputError(f"{path}: cannot open ({e.strerror})") from None
    except ValueError as e:
        raise InputError(f"{path}: not JSON ({e})") from None
    if not isinstance(report, dict) or not isinstance(report.get("verify"), dict):
        raise InputError(f"{path}: no \"verify\" section (not a tools/calibrate report)")
    protos = {p.name: p for p in (thermcal.FULL, thermcal.QUICK)}
    if report.get("protocol") not in protos:
        raise InputError(f"{path}: protocol {report.get('protocol')!r} is none of "
                         f"{', '.join(protos)}")
    folder = cli.out_dir(os.path.join(out_dir, FOLDER))
    return Context(out_dir, folder, report, protos[report["protocol"]])


def clear(out_dir):
    """Remove an earlier run's report files: a series not made now must not look made."""
    for name in FILES:
        path = os.path.join(out_dir, FOLDER, name)
        if os.path.exists(path):
            os.remove(path)


def series_run(ctx, key):
    """The command and seed of the verification run behind a series (report.json)."""
    run = ctx.verify.get(key)
    if not isinstance(run, dict):
        raise InputError(f"{os.path.join(ctx.out, 'report.json')}: no verify.{key} section")
    return {"command": run.get("command"), "seed": run.get("seed")}


DEFINITIONS = {
    "turn_on_time_s": "from power-on (t_s = 0) to the first sample after which rate_valid "
                      "stays 1 until the input first moves or the self-test starts",
    "time_to_error_bound_s": "from power-on to the first sample after which |rate_dps - "
                             "rate_true_dps| <= error_bound_dps (the verification's worst "
                             "valid error) over the same rest, valid or not",
    "drive_locked_s": "from power-on to the first sample after which the drive stays LOCKED "
                      "(no MODE reason)",
}


def _plots():
    """The figures' module, imported when a figure is drawn: matplotlib's import costs
    tools/calibrate half a second at every start, --help and refusals included."""
    from . import ieee1431_plots
    return ieee1431_plots


def turn_on_series(ctx):
    plots = _plots()
    log = ctx.log("verify.csv")
    run = series_run(ctx, "rate")
    bound = (ctx.verify["rate"].get("limits") or {}).get("worst_valid_error_dps",
                                                         calflow.VERIFY_MAX_ERR_DPS)
    figs = figures.turn_on(log, float(bound))
    png = plots.turn_on(ctx, log, figures.turn_on_window(log, figs), figs, run)
    return {"clause": "IEEE 1431 12.5 turn-on time", **run, "log": ctx.rel(log.path),
            "png": ctx.rel(png), "definitions": DEFINITIONS, **figs}


def warm_up_series(ctx):
    plots = _plots()
    log = ctx.log("verify_warmup.csv")
    run = series_run(ctx, "warmup")
    figs = thermcal.verify_warmup(log, ctx.protocol)
    png = plots.warm_up(ctx, log, figs, run)
    return {"clause": "IEEE 1431 12.6 warm-up time", **run, "log": ctx.rel(log.path),
            "png": ctx.rel(png),
            "how": "a cold start at rest (plant.cold_start: every thermal node at the ambient "
                   "at power-on); warm-up time: the start of the first 1 s bin from power-on "
                   "after which every bin's mean of the valid rate_dps lies within bound_dps "
                   "of the input; warmup_time_avg_s: the time after which the valid "
                   "rate_dps averaged over the preceding warmup_avg_s lies within bound_dps "
                   "(a late 1 s excursion of the noise does not move it); raw_settle_time_s: "
                   "the same as the first for rate_unc_dps against its own final level (its "
                   "last 60 s)", **figs}


def scale_factor_series(ctx):
    plots = _plots()
    log = ctx.log("verify.csv")
    run = series_run(ctx, "rate")
    res, figs = figures.scale_factor(log)
    png = plots.scale_factor(ctx, res, run)
    v = ctx.verify["rate"]
    return {"clause": "IEEE 1431 12.9 scale factor test series", **run, "log": ctx.rel(log.path),
            "png": ctx.rel(png),
            "how": "held means of the valid output before the self-test, each rate against "
                   "the rests around it (at the rests' mean level); least squares over the "
                   "rates (scalefactor.fit); nonlinearity: input-referred residual / full "
                   "scale; bias: the line's intercept; the rests' means apart",
            **figs,
            "verdict": {"scale_factor_error_ppm_20_160": v.get("scale_factor_ppm"),
                        "subrange_worst": v.get("subrange_worst"), "passed": v.get("passed")}}


def drift_series(ctx):
    plots = _plots()
    log = ctx.log("verify_noise.csv")
    run = series_run(ctx, "noise")
    figs, res, means = figures.drift(log)
    png = plots.drift(ctx, res, means, run)
    return {"clause": "IEEE 1431 12.11 drift rate test series (IEEE 952 coefficients)", **run,
            "log": ctx.rel(log.path), "png": ctx.rel(png),
            "how": "Allan deviation as tools/gyro-allan (allan.analyse, allan.ieee952) of "
                   "rate_dps (compensated) and rate_unc_dps (not), the same run at 25 degC",
            **figs}


def _part(fn):
    """fn(), or {"error": why} when its log cannot give it."""
    try:
        return fn()
    except InputError as e:
        return {"error": str(e)}


def _plateaus(ctx):
    log = ctx.log("verify_plateaus.csv")
    return {**series_run(ctx, "thermal_plateaus"), "log": ctx.rel(log.path),
            **figures.plateaus(log, ctx.protocol)}


def _ramp(ctx):
    log = ctx.log("verify_ramp.csv")
    return {**series_run(ctx, "thermal_ramp"), "log": ctx.rel(log.path),
            **figures.ramp(log, ctx.protocol)}


def temperature_series(ctx):
    """The plateaus and the ramp, each on its own log: one of them is drawn without the
    other (its panel says why), and each one missing is a problem of its own."""
    pl, rp = _part(lambda: _plateaus(ctx)), _part(lambda: _ramp(ctx))
    entry = {"clause": "IEEE 1431 12.8 operating temperature test series", "plateaus": pl,
             "ramp": rp, "errors": [x["error"] for x in (pl, rp) if "error" in x]}
    if len(entry["errors"]) == 2:
        return dict(entry, error="neither the plateaus nor the ramp could be read")
    return dict(entry, png=ctx.rel(_plots().temperature(ctx, pl, rp)))


SECTIONS = (("turn_on", turn_on_series, ("verify.csv",)),
            ("warm_up", warm_up_series, ("verify_warmup.csv",)),
            ("scale_factor", scale_factor_series, ("verify.csv",)),
            ("drift", drift_series, ("verify_noise.csv",)),
            ("temperature", temperature_series, ("verify_plateaus.csv", "verify_ramp.csv")))


def _section(ctx, name, fn, logs):
    """(entry, problems): a series, or {"error"} with the file and why; each problem
    names the series too ("drift: DIR/work/verify_noise.csv: cannot open ..."). A
    numerical failure on data that parsed (a fit on a degenerate log) is named with its
    logs."""
    try:
        entry = fn(ctx)
    except InputError as e:
        entry = {"error": str(e)}
    except ValueError as e:  # numpy's LinAlgError among them
        entry = {"error": f"{', '.join(os.path.join(ctx.out, 'work', n) for n in logs)}: "
                          f"cannot be analysed ({type(e).__name__}: {e})"}
    why = entry.get("errors") or ([entry["error"]] if "error" in entry else [])
    return entry, [f"{name}: {w}" for w in why]


def write(out_dir, calibration=None):
    """Write DIR/ieee1431/ (module doc) for the calibration file `calibration` (default:
    report.json's verify_only): (path of ieee1431.json, its content, the problems: one
    line per series not written or written in part, naming the file and why).
    InputError only when DIR/report.json is missing or no verification's."""
    clear(out_dir)
    ctx = load(out_dir)
    doc = {"standard": "shaped after IEEE Std 1431-2004 clause 12 (turn-on time, warm-up time, "
                       "scale factor, drift rate and operating temperature test series); noise "
                       "coefficients "
                       "after IEEE Std 952-1997",
           "part": ctx.part(), "sets": ctx.sets(),
           "calibration": calibration or ctx.report.get("verify_only"), "protocol": ctx.protocol.name,
           "command": ctx.report.get("command"), "report": ctx.rel(os.path.join(out_dir,
                                                                               "report.json"))}
    problems = []
    for name, fn, logs in SECTIONS:
        doc[name], p = _section(ctx, name, fn, logs)
        problems += p
    doc["problems"] = problems
    return cli.write_json(ctx.folder, "ieee1431.json", doc), doc, problems


def _f(x, spec):
    return "n/a" if x is None or not np.isfinite(x) else format(x, spec)


def summary(doc):
    """One printed line per series written (the figures a reader looks for first)."""
    out = []
    t = doc.get("turn_on", {})
    if "error" not in t:
        out.append(f"turn-on time {_f(t['turn_on_time_s'], '.3g')} s (valid for good), within "
                   f"{t['error_bound_dps']:g} deg/s of the input at "
                   f"{_f(t['time_to_error_bound_s'], '.3g')} s")
    w = doc.get("warm_up", {})
    if "error" not in w:
        out.append(f"warm-up time {_f(w['warmup_time_s'], '.3g')} s from a cold start (1 s means "
                   f"within {w['bound_dps']:g} deg/s for good; the raw output "
                   f"{_f(w['raw_settle_time_s'], '.3g')} s)")
    s = doc.get("scale_factor", {})
    if "error" not in s:
        out.append(f"scale factor {s['scale_factor_error_ppm']:+.0f} ppm over +-"
                   f"{s['full_scale_dps']:g} deg/s, bias {s['bias_dps']:+.4f} deg/s, "
                   f"nonlinearity {s['nonlinearity_rms_percent_fs']:.3f} % FS rms "
                   f"({s['nonlinearity_max_percent_fs']:.3f} max), asymmetry "
                   f"{s['asymmetry_ppm']:+.0f} ppm")
    d = doc.get("drift", {})
    if "error" not in d:
        ieee = d["rate_dps"]["ieee952"]
        out.append("drift, compensated, IEEE 952: " + "; ".join(
            f"{k} " + ("n/a" if ieee[k]["value"] is None else f"{ieee[k]['value']:.3g} {ieee[k]['unit']}")
            for k in "NBKR"))
    tp = doc.get("temperature", {})
    if "error" not in tp and "error" not in tp.get("plateaus", {"error": 1}):
        out.append("plateaus: " + ", ".join(
            f"{r['ambient_c']:g} degC {r['bias_dps']:+.3f} deg/s {r['scale_factor_error_ppm']:+.0f} ppm"
            for r in tp["plateaus"]["plateaus"]))
    if "error" not in tp and "error" not in tp.get("ramp", {"error": 1}):
        r = tp["ramp"]
        slope = [v for k, v in r.items() if k.startswith("bias_slope_dps_per_k")]
        out.append(f"ramp: 1 s bias means {r['bias_1s_std_dps']:.3f} deg/s std, slope "
                   f"{_f(slope[0] if slope else None, '+.4f')} deg/s/K")
    return out


def pngs(doc):
    """The PNGs written, relative to DIR/ieee1431/."""
    return [doc[name]["png"] for name, _, _ in SECTIONS if "png" in doc.get(name, {})]
