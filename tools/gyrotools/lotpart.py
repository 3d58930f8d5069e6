"""One part of a lot, run on a worker: the calibration flow, then the scenarios.

run_part(job) is pure in the part's index: it empties the part's folder first, so a
retry after a dead worker starts from nothing. It runs `tools/calibrate --sim` (when the
flow calibrates) and each scenario as its own gyro-sim process, loading the calibration
written, and returns the part's deterministic values (row: drawn parameters, seed, every
figure, the calibration written, why the flow stopped) apart from what depends on the
host (timing: wall times, host name).

A figure that a run did not give is NaN ("not measured"), never a pass: the report
counts it apart. The part's flow is bounded by job.timeout_s in all; past it the part
raises PartTimeout, and a process ended from outside (Ctrl-C, kill) PartInterrupted:
no row is kept, and Dask may retry it.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import time

NAN = float("nan")

# Calibration figures: column -> path in calibrate's report.json.
CAL_FIGURES = {
    "cal.selfcal_s": ("selfcal", "s"),
    "cal.selfcal_f0_hz": ("selfcal", "f0_hz"),
    "cal.selfcal_q": ("selfcal", "q"),
    "cal.sf_ppm": ("verify", "rate", "scale_factor_ppm"),
    "cal.subrange_worst_ppm": ("verify", "rate", "subrange_worst", "slope_ppm"),
    "cal.bias_at_rest_dps": ("verify", "rate", "bias_at_rest_dps"),
    "cal.valid_fraction": ("verify", "rate", "valid_fraction_in_dwell"),
    "cal.worst_valid_error_dps": ("verify", "rate", "worst_valid_error_dps"),
    "cal.ramp_bias_std_dps": ("verify", "thermal_ramp", "bias_1s_std_dps"),
    "cal.transient_bias_std_dps": ("verify", "thermal_transient", "bias_1s_std_dps"),
    "cal.noise_ratio_1s": ("verify", "noise", "ratio"),
    "cal.warmup_time_s": ("verify", "warmup", "warmup_time_s"),
}


# Exit statuses of a process ended from outside (Ctrl-C, kill, a closing worker): the
# part's result would say nothing about the part, so none is kept.
ENDED_FROM_OUTSIDE = {-signal.SIGINT, -signal.SIGTERM, -signal.SIGKILL, -signal.SIGHUP, 130, 143}


class PartTimeout(RuntimeError):
    """The part's flow ran past its time limit."""


class PartInterrupted(RuntimeError):
    """A process of the part was ended from outside."""


@dataclasses.dataclass(frozen=True)
class PartJob:
    part: int
    values: dict          # drawn plant.KEY -> value
    base: dict            # fixed plant.KEY / firmware.KEY -> value
    seed: int
    calibrate: bool
    quick: bool
    scenarios: tuple      # lotfile.Scenario
    gyro_sim: str
    tools_dir: str
    part_dir: str
    timeout_s: float
    stamp: str
    drive: str = "auto"   # tools/calibrate --drive


def _get(obj, path):
    for k in path:
        if not isinstance(obj, dict) or k not in obj:
            return None
        obj = obj[k]
    return obj


def _float(v) -> float:
    if isinstance(v, bool):
        return float(v)
    if isinstance(v, (int, float)) and math.isfinite(v):
        return float(v)
    return NAN


def _max_abs(items, key) -> float:
    vals = [abs(_float(p.get(key))) for p in items or [] if isinstance(p, dict)]
    vals = [v for v in vals if not math.isnan(v)]
    return max(vals) if vals else NAN


def cal_figures(report: dict) -> dict:
    """The figures of calibrate's report.json; what it lacks is NaN."""
    out = {k: _float(_get(report, path)) for k, path in CAL_FIGURES.items()}
    nl = _float(_get(report, ("verify", "rate", "nonlinearity_fs")))
    out["cal.nonlinearity_pct_fs"] = nl * 100.0
    plateaus = _get(report, ("verify", "thermal_plateaus", "plateaus"))
    out["cal.temp_bias_max_dps"] = _max_abs(plateaus, "bias_dps")
    out["cal.temp_sf_max_ppm"] = _max_abs(plateaus, "sf_ppm")
    return out


def scenario_figures(name: str, figures: dict) -> dict:
    """Every scalar figure of a gyro-sim JSON as NAME.KEY (null -> NaN)."""
    return {f"{name}.{k}": _float(v) for k, v in figures.items()
            if v is None or isinstance(v, (bool, int, float))}


def _sets(d: dict) -> list:
    out = []
    for k, v in d.items():
        out += ["--set", f"{k}={v if isinstance(v, str) else repr(float(v))}"]
    return out


def part_settings(job: PartJob, plant_only: bool = False) -> dict:
    """The part's settings: its own board (the converters' INL patterns, plant.board_seed,
    drawn from the part's seed, so the same board in its calibration and in every run
    after it; a lot that sets plant.board_seed keeps its own), the lot's base and the
    part's draws."""
    base = {k: v for k, v in job.base.items() if k.startswith("plant.") or not plant_only}
    return {"plant.board_seed": str(job.seed % 1000000000), **base, **job.values}


def _kill_tree(p: subprocess.Popen):
    """Ends a process and what it started (tools/calibrate runs gyro-sim). Kept in the
    caller's process group, so that a Ctrl-C at the terminal reaches them all too."""
    import psutil  # a dependency of distributed
    try:
        kids = psutil.Process(p.pid).children(recursive=True)
    except psutil.NoSuchProcess:
        kids = []
    for c in kids + [p]:
        try:
            c.kill()
        except (psutil.NoSuchProcess, ProcessLookupError):
            pass
    p.communicate()


class _Runner:
    """Runs the part's processes against one deadline, timing each."""

    def __init__(self, job: PartJob):
        self.job, self.t0 = job, time.monotonic()
        self.stages, self.commands = {}, []

    def run(self, stage: str, cmd: list, cwd: str) -> subprocess.CompletedProcess:
        left = self.job.timeout_s - (time.monotonic() - self.t0)
        if left <= 0:
            raise PartTimeout(f"part {self.job.part}: over {self.job.timeout_s:g} s before {stage}")
        self.commands.append(shlex.join(cmd))
        t = time.monotonic()
        p = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            out, err = p.communicate(timeout=left)
        except subprocess.TimeoutExpired:
            _kill_tree(p)
            raise PartTimeout(f"part {self.job.part}: {stage} still running after the part's "
                              f"{self.job.timeout_s:g} s") from None
        if p.returncode in ENDED_FROM_OUTSIDE:
            raise PartInterrupted(f"part {self.job.part}: {stage} ended from outside (exit {p.returncode})")
        r = subprocess.CompletedProcess(cmd, p.returncode, out, err)
        self.stages[f"{stage}_wall_s"] = time.monotonic() - t
        return r


def _reason(stage: str, r, part_dir: str) -> str:
    lines = [ln for ln in (r.stderr or "").splitlines() if ln.strip()]
    last = lines[-1].replace(part_dir, ".")[:200] if lines else ""
    return f"{stage}: exit {r.returncode}" + (f" ({last})" if last else "")


def _calibrate(job: PartJob, runner: _Runner, row: dict) -> str | None:
    """Runs the calibration flow; returns the parameter set to load (None: none)."""
    out = os.path.join(job.part_dir, "cal")
    cmd = [sys.executable, os.path.join(job.tools_dir, "calibrate"), "--sim",
           *_sets(part_settings(job, plant_only=True)), "--seed", str(job.seed), "--out", out,
           "--gyro-sim", job.gyro_sim] + (["--quick"] if job.quick else []) + (
               ["--drive", job.drive] if job.drive != "auto" else [])
    r = runner.run("cal", cmd, job.part_dir)
    row["cal.exit"] = float(r.returncode)
    row["cal.verified"] = 1.0 if r.returncode == 0 else 0.0
    try:
        with open(os.path.join(out, "report.json"), encoding="utf-8") as fh:
            row.update(cal_figures(json.load(fh)))
    except (OSError, ValueError):
        row.update(cal_figures({}))
    for name in ("calibration.json", "calibration_unverified.json"):
        path = os.path.join(out, name)
        if os.path.isfile(path):
            _written(path, row, runner.stages)
            if r.returncode != 0:
                row["flow_error"].append(_reason("calibration", r, job.part_dir))
            return path
    row["flow_error"].append(_reason("calibration", r, job.part_dir))
    return None


# Values of the calibration written that the calendar decides, not the part: kept with
# the timings.
CAL_HOST_FACTS = {"cal.date"}


def _written(path: str, row: dict, host: dict):
    """The calibration written, as calw.NAME columns (its date in host)."""
    with open(path, encoding="utf-8") as fh:
        ps = json.load(fh)
    for e in ps.get("params", []):
        (host if e["name"] in CAL_HOST_FACTS else row)[f"calw.{e['name']}"] = _float(e.get("value"))


def _scenario_duration(path: str):
    with open(path, encoding="utf-8") as fh:
        return json.load(fh).get("duration_s")


def _scenario(job: PartJob, runner: _Runner, i: int, sc, params: str | None, row: dict):
    out = os.path.join(job.part_dir, f"{sc.name}.json")
    dur = sc.quick_duration_s if job.quick and sc.quick_duration_s else sc.duration_s
    cmd = [job.gyro_sim, "--scenario", sc.path, "--seed", str(job.seed + 5000 + i),
           "--json", out, "--quiet", *_sets(part_settings(job))]
    cmd += (["--duration", repr(float(dur))] if dur else []) + (["--selfcal"] if sc.selfcal else [])
    cmd += ["--firmware-params", params] if params else []
    r = runner.run(sc.name, cmd, job.part_dir)
    try:
        with open(out, encoding="utf-8") as fh:
            figures = json.load(fh).get("figures", {})
        row.update(scenario_figures(sc.name, figures))
        sim = _float(dur or _scenario_duration(sc.path)) + _float(figures.get("selfcal_s") or 0)
        runner.stages["sim_s"] = runner.stages.get("sim_s", 0.0) + sim
    except (OSError, ValueError, AttributeError):
        pass
    if r.returncode != 0:
        row["flow_error"].append(_reason(sc.name, r, job.part_dir))


def run_part(job: PartJob) -> dict:
    """{"row": deterministic values, "timing": host facts, "commands": [...]}"""
    started = time.time()
    shutil.rmtree(job.part_dir, ignore_errors=True)
    os.makedirs(job.part_dir)
    runner = _Runner(job)
    row = {"part": job.part, **job.values, "seed": job.seed, "flow_error": []}
    params = _calibrate(job, runner, row) if job.calibrate else None
    for i, sc in enumerate(job.scenarios):
        if job.calibrate and params is None:
            row["flow_error"].append(f"{sc.name}: not run (no calibration)")
            continue
        _scenario(job, runner, i, sc, params, row)
    row["flow_error"] = "; ".join(row["flow_error"])
    row["stamp"] = job.stamp
    timing = {"part": job.part, "host": socket.gethostname(), "pid": os.getpid(),
              "started_unix_s": started, "wall_s": time.monotonic() - runner.t0,
              **runner.stages}
    return {"row": row, "timing": timing, "commands": runner.commands}
