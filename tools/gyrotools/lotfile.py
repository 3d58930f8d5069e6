"""A wafer lot in simulation: the lot file and its spec, validated, and the parts drawn.

The lot file (JSON; examples/lot/README.md describes it) names the plant parameters that
vary from part to part, each with its distribution and bounds, optional correlations
between them (a Gaussian copula: correlated standard normals, each mapped through its
marginal's inverse CDF, truncated to its bounds), the fixed settings, the flow run on
every part (calibration, characterisation scenarios) and the spec file (limits on the
figures). Everything is checked before anything runs; a problem is an InputError with
one line saying where.

Part k is drawn from numpy's SeedSequence([lot seed, k]) alone: the same part whatever
the number of workers, the order they finish or the parts drawn before it.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
import re
import subprocess

import numpy as np
from scipy import stats

from .errors import InputError

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
LOT_KEYS = {"name", "seed", "parts", "base", "distributions", "correlations", "spec",
            "flow", "timeout_s", "description", "notes"}
LOT_REQUIRED = {"name", "seed", "distributions", "spec", "flow"}
DIST_KEYS = {"normal": ({"mean", "sd"}, {"min", "max"}),
             "uniform": ({"min", "max"}, set()),
             "lognormal": ({"median", "sigma_ln"}, {"min", "max"})}
FLOW_KEYS = {"calibrate", "scenarios", "drive"}
DRIVES = ("auto", "fixed", "tracking")  # tools/calibrate --drive
SCEN_KEYS = {"name", "scenario", "duration_s", "quick_duration_s", "selfcal"}
LINE_KEYS = {"figure", "min", "max", "unit", "note"}
SPEC_KEYS = {"name", "lines", "notes", "description"}
NAME_RE = re.compile(r"^[a-z][a-z0-9_]{0,31}$")
MAX_PARTS = 1_000_000
LIST_RE = re.compile(r"^((?:plant|firmware)\.\S+)\s+(\S+)\s+\[([^\]]*)\]\s*(.*)$")


@dataclasses.dataclass(frozen=True)
class SimParam:
    """One gyro-sim parameter as --list-params gives it."""
    key: str
    lo: float | None = None
    hi: float | None = None
    choices: tuple = ()
    unit: str = ""


@dataclasses.dataclass(frozen=True)
class Dist:
    """One varying parameter: its frozen scipy marginal truncated to [lo, hi]."""
    key: str
    marginal: object
    lo: float
    hi: float

    def ppf(self, u: float) -> float:
        """The truncated marginal's inverse CDF (u in (0, 1))."""
        a, b = self.marginal.cdf(self.lo), self.marginal.cdf(self.hi)
        x = float(self.marginal.ppf(a + u * (b - a)))
        return min(max(x, self.lo), self.hi)


@dataclasses.dataclass(frozen=True)
class Scenario:
    name: str
    path: str
    duration_s: float | None
    quick_duration_s: float | None
    selfcal: bool


@dataclasses.dataclass(frozen=True)
class SpecLine:
    figure: str
    lo: float | None
    hi: float | None
    unit: str = ""

    def text(self) -> str:
        if self.lo is not None and self.hi is not None:
            return f"{self.lo:g} <= {self.figure} <= {self.hi:g} {self.unit}".rstrip()
        if self.lo is not None:
            return f"{self.figure} >= {self.lo:g} {self.unit}".rstrip()
        return f"{self.figure} <= {self.hi:g} {self.unit}".rstrip()


@dataclasses.dataclass(frozen=True)
class Lot:
    path: str
    name: str
    seed: int
    parts: int
    base: dict
    dists: tuple
    chol: np.ndarray
    calibrate: bool
    scenarios: tuple
    spec_path: str
    spec: tuple
    timeout_s: float
    digest: str
    units: dict
    drive: str = "auto"  # the drive mode the calibration flow calibrates (--drive)


# ---------------------------------------------------------------- gyro-sim's table

def sim_params(gyro_sim: str) -> dict:
    """{key: SimParam} from `gyro-sim --list-params`."""
    try:
        r = subprocess.run([gyro_sim, "--list-params"], capture_output=True, text=True,
                           timeout=60)
    except (OSError, subprocess.TimeoutExpired) as e:
        raise InputError(f"{gyro_sim}: cannot run it ({e}); build it with tools/run-sim") from None
    if r.returncode != 0:
        raise InputError(f"{gyro_sim} --list-params: exit {r.returncode}")
    return parse_param_list(r.stdout)


def parse_param_list(text: str) -> dict:
    out = {}
    for line in text.splitlines():
        m = LIST_RE.match(line)
        if not m:
            continue
        key, rng, rest = m.group(1), [s.strip() for s in m.group(3).split(",")], m.group(4)
        unit = rest.split("  ")[0].strip() if "  " in rest else ""
        try:
            out[key] = SimParam(key, float(rng[0]), float(rng[1]), unit=unit)
        except (ValueError, IndexError):
            out[key] = SimParam(key, choices=tuple(rng), unit=unit)
    return out


# ---------------------------------------------------------------- JSON and numbers

def _no_constant(name):
    raise InputError(f"{name} is not a JSON number")


def _pairs(pairs):
    keys = [k for k, _ in pairs]
    dup = {k for k in keys if keys.count(k) > 1}
    if dup:
        raise InputError(f"key '{sorted(dup)[0]}' given twice")
    return dict(pairs)


def read_json(path: str, what: str) -> dict:
    """A JSON object from a file; NaN, Infinity and duplicate keys refused."""
    try:
        with open(path, encoding="utf-8") as fh:
            text = fh.read()
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{path}: cannot read the {what} ({getattr(e, 'strerror', e)})") from None
    try:
        obj = json.loads(text, parse_constant=_no_constant, object_pairs_hook=_pairs)
    except json.JSONDecodeError as e:
        raise InputError(f"{path}:{e.lineno}: not valid JSON ({e.msg})") from None
    except InputError as e:
        raise InputError(f"{path}: {e}") from None
    if not isinstance(obj, dict):
        raise InputError(f"{path}: the {what} must be a JSON object")
    return obj


def num(v, where: str, lo=None, hi=None, integer=False, open_lo=False) -> float:
    """A finite number (an int when integer), within [lo, hi] (lo excluded if open_lo)."""
    ok = isinstance(v, int) if integer else isinstance(v, (int, float))
    if isinstance(v, bool) or not ok:
        raise InputError(f"{where}: {json.dumps(v)[:40]} is not {'an integer' if integer else 'a number'}")
    if not math.isfinite(v):
        raise InputError(f"{where}: {v} is not finite")
    if lo is not None and (v <= lo if open_lo else v < lo):
        raise InputError(f"{where}: {v:g} is below {'or at ' if open_lo else ''}{lo:g}")
    if hi is not None and v > hi:
        raise InputError(f"{where}: {v:g} is above {hi:g}")
    return v


def keys_ok(obj, where: str, allowed: set, required: set):
    if not isinstance(obj, dict):
        raise InputError(f"{where}: must be a JSON object")
    extra = sorted(set(obj) - allowed)
    if extra:
        raise InputError(f"{where}: unknown key '{extra[0]}' (allowed: {', '.join(sorted(allowed))})")
    missing = sorted(required - set(obj))
    if missing:
        raise InputError(f"{where}: missing key '{missing[0]}'")


# ---------------------------------------------------------------- the parts' values

def _param(key: str, table: dict, where: str, plant_only=True) -> SimParam:
    if plant_only and not key.startswith("plant."):
        raise InputError(f"{where}: '{key}' is not a plant parameter (plant.KEY)")
    if key not in table:
        raise InputError(f"{where}: '{key}' is not a gyro-sim parameter (gyro-sim --list-params)")
    return table[key]


def _base(obj, table: dict, where: str) -> dict:
    if not isinstance(obj, dict):
        raise InputError(f"{where}: must be a JSON object of \"plant.KEY\": value")
    out = {}
    for key, v in obj.items():
        p = _param(key, table, f"{where}.{key}", plant_only=False)
        if p.choices:
            if v not in p.choices:
                raise InputError(f"{where}.{key}: {json.dumps(v)} is not one of {', '.join(p.choices)}")
            out[key] = v
        else:
            out[key] = num(v, f"{where}.{key}", p.lo, p.hi)
    return out


def _marginal(d: dict, where: str):
    kind = d["dist"]
    if kind == "normal":
        return stats.norm(num(d["mean"], f"{where}.mean"), num(d["sd"], f"{where}.sd", 0, open_lo=True))
    if kind == "uniform":
        lo, hi = num(d["min"], f"{where}.min"), num(d["max"], f"{where}.max")
        if not lo < hi:
            raise InputError(f"{where}: min {lo:g} must be below max {hi:g}")
        return stats.uniform(lo, hi - lo)
    med = num(d["median"], f"{where}.median", 0, open_lo=True)
    return stats.lognorm(num(d["sigma_ln"], f"{where}.sigma_ln", 0, 10, open_lo=True), scale=med)


def _dist(key: str, d, table: dict, where: str) -> Dist:
    p = _param(key, table, where)
    if p.choices:
        raise InputError(f"{where}: '{key}' takes names ({', '.join(p.choices)}), not a distribution")
    if not isinstance(d, dict) or d.get("dist") not in DIST_KEYS:
        raise InputError(f"{where}.dist: must be one of {', '.join(DIST_KEYS)}")
    req, opt = DIST_KEYS[d["dist"]]
    keys_ok(d, where, req | opt | {"dist", "note"}, req | {"dist"})
    marginal = _marginal(d, where)
    lo = num(d.get("min", p.lo), f"{where}.min", p.lo, p.hi)
    hi = num(d.get("max", p.hi), f"{where}.max", p.lo, p.hi)
    if not lo < hi:
        raise InputError(f"{where}: min {lo:g} must be below max {hi:g}")
    if marginal.cdf(hi) - marginal.cdf(lo) < 1e-9:
        raise InputError(f"{where}: the bounds [{lo:g}, {hi:g}] hold no probability of the distribution")
    return Dist(key, marginal, lo, hi)


def _chol(corr, dists: tuple, where: str) -> np.ndarray:
    n = len(dists)
    m = np.eye(n)
    index = {d.key: i for i, d in enumerate(dists)}
    if not isinstance(corr, list):
        raise InputError(f"{where}: must be a list of {{\"a\", \"b\", \"rho\"}}")
    for j, c in enumerate(corr):
        w = f"{where}[{j}]"
        keys_ok(c, w, {"a", "b", "rho", "note"}, {"a", "b", "rho"})
        a, b = c["a"], c["b"]
        for x in (a, b):
            if not isinstance(x, str) or x not in index:
                raise InputError(f"{w}: '{x}' is not one of the distributions' parameters")
        if a == b or m[index[a], index[b]] != 0.0:
            raise InputError(f"{w}: the pair {a}, {b} is {'the same parameter' if a == b else 'given twice'}")
        m[index[a], index[b]] = m[index[b], index[a]] = num(c["rho"], f"{w}.rho", -1, 1)
    try:
        return np.linalg.cholesky(m)
    except np.linalg.LinAlgError:
        ev = np.linalg.eigvalsh(m).min()
        raise InputError(f"{where}: the correlation matrix is not positive definite "
                         f"(smallest eigenvalue {ev:.3g})") from None


def draw(lot: Lot, k: int) -> tuple:
    """Part k: ({key: value} of the varying parameters, its noise seed)."""
    ss_values, ss_noise = np.random.SeedSequence([lot.seed, k]).spawn(2)
    z = lot.chol @ np.random.default_rng(ss_values).standard_normal(len(lot.dists))
    u = stats.norm.cdf(z)
    values = {d.key: d.ppf(float(ui)) for d, ui in zip(lot.dists, u)}
    seed = int(ss_noise.generate_state(1)[0]) % (1 << 30) + 1
    return values, seed


# ---------------------------------------------------------------- flow and spec

def _scenarios(obj, folder: str, where: str) -> tuple:
    if not isinstance(obj, list):
        raise InputError(f"{where}: must be a list")
    out, seen = [], set()
    for j, s in enumerate(obj):
        w = f"{where}[{j}]"
        keys_ok(s, w, SCEN_KEYS, {"name"})
        name = s["name"]
        if not isinstance(name, str) or not NAME_RE.match(name) or name in ("cal", "calw", "pass"):
            raise InputError(f"{w}.name: must be a lower-case identifier other than cal, calw, pass")
        if name in seen:
            raise InputError(f"{w}.name: '{name}' given twice")
        seen.add(name)
        rel = s.get("scenario")
        if rel is not None and not isinstance(rel, str):
            raise InputError(f"{w}.scenario: must be a path")
        path = (os.path.join(folder, rel) if rel else
                os.path.join(ROOT, "host_sim/scenarios", f"{name}.json"))
        if not os.path.isfile(path):
            raise InputError(f"{w}.scenario: {path}: no such file")
        dur = [None if s.get(x) is None else num(s[x], f"{w}.{x}", 0, 1e7, open_lo=True)
               for x in ("duration_s", "quick_duration_s")]
        if not isinstance(s.get("selfcal", False), bool):
            raise InputError(f"{w}.selfcal: must be true or false")
        out.append(Scenario(name, os.path.abspath(path), dur[0], dur[1], s.get("selfcal", False)))
    return tuple(out)


def _flow(obj, folder: str, where: str) -> tuple:
    keys_ok(obj, where, FLOW_KEYS, {"calibrate", "scenarios"})
    if not isinstance(obj["calibrate"], bool):
        raise InputError(f"{where}.calibrate: must be true or false")
    scen = _scenarios(obj["scenarios"], folder, f"{where}.scenarios")
    if not scen and not obj["calibrate"]:
        raise InputError(f"{where}: nothing to run (no calibration and no scenario)")
    drive = obj.get("drive", "auto")
    if drive not in DRIVES:
        raise InputError(f"{where}.drive: one of {', '.join(DRIVES)} (the drive mode the "
                         "calibration flow calibrates)")
    if drive != "auto" and not obj["calibrate"]:
        raise InputError(f"{where}.drive: only with calibrate true (it is the flow's choice)")
    return obj["calibrate"], scen, drive


def _line(o, where: str, prefixes: set | None) -> SpecLine:
    keys_ok(o, where, LINE_KEYS, {"figure"})
    fig = o["figure"]
    if not isinstance(fig, str) or "." not in fig or (prefixes is not None and fig.split(".", 1)[0] not in prefixes):
        raise InputError(f"{where}.figure: {json.dumps(fig)[:60]} must be SOURCE.NAME with "
                         f"SOURCE one of {', '.join(sorted(prefixes or []))}")
    lo = None if o.get("min") is None else num(o["min"], f"{where}.min")
    hi = None if o.get("max") is None else num(o["max"], f"{where}.max")
    if lo is None and hi is None:
        raise InputError(f"{where}: a line needs min, max or both")
    if lo is not None and hi is not None and not lo < hi:
        raise InputError(f"{where}: min {lo:g} must be below max {hi:g}")
    unit = o.get("unit", "")
    if not isinstance(unit, str):
        raise InputError(f"{where}.unit: must be a string")
    return SpecLine(fig, lo, hi, unit)


def load_spec(path: str, scenario_names=None) -> tuple:
    """The spec's lines; a figure is cal.NAME or SCENARIO.NAME of the flow (any
    SOURCE.NAME when scenario_names is None)."""
    obj = read_json(path, "spec file")
    keys_ok(obj, path, SPEC_KEYS, {"lines"})
    if not isinstance(obj["lines"], list) or not obj["lines"]:
        raise InputError(f"{path}: lines must be a non-empty list")
    prefixes = None if scenario_names is None else {"cal"} | set(scenario_names)
    lines = tuple(_line(o, f"{path}: lines[{j}]", prefixes) for j, o in enumerate(obj["lines"]))
    figs = [ln.figure for ln in lines]
    dup = [f for f in figs if figs.count(f) > 1]
    if dup:
        raise InputError(f"{path}: figure '{dup[0]}' has two lines (give one line min and max)")
    return lines


# ---------------------------------------------------------------- the whole file

def _digest(obj: dict, scenarios: tuple) -> str:
    """What makes the parts' values: the lot minus its part count, timeout and notes,
    and the scenario files' contents (the spec is applied afterwards)."""
    keep = {k: v for k, v in obj.items() if k not in ("parts", "timeout_s", "notes", "description", "spec")}
    h = hashlib.sha256(json.dumps(keep, sort_keys=True).encode())
    for s in scenarios:
        with open(s.path, "rb") as fh:
            h.update(fh.read())
    return h.hexdigest()


def load(path: str, table: dict) -> Lot:
    """The lot file at path, checked against gyro-sim's parameter table."""
    obj = read_json(path, "lot file")
    keys_ok(obj, path, LOT_KEYS, LOT_REQUIRED)
    folder = os.path.dirname(os.path.abspath(path))
    if not isinstance(obj["name"], str) or not obj["name"]:
        raise InputError(f"{path}: name must be a non-empty string")
    seed = int(num(obj["seed"], f"{path}: seed", 0, 2**63 - 1, integer=True))
    parts = int(num(obj.get("parts", 16), f"{path}: parts", 1, MAX_PARTS, integer=True))
    timeout = num(obj.get("timeout_s", 3600), f"{path}: timeout_s", 0, 1e6, open_lo=True)
    base = _base(obj.get("base", {}), table, f"{path}: base")
    dd = obj["distributions"]
    if not isinstance(dd, dict) or not dd:
        raise InputError(f"{path}: distributions must be a non-empty object")
    dists = tuple(_dist(k, v, table, f"{path}: distributions.{k}") for k, v in dd.items())
    both = sorted(set(base) & set(dd))
    if both:
        raise InputError(f"{path}: '{both[0]}' is both fixed (base) and varying (distributions)")
    chol = _chol(obj.get("correlations", []), dists, f"{path}: correlations")
    calibrate, scen, drive = _flow(obj["flow"], folder, f"{path}: flow")
    if not isinstance(obj["spec"], str):
        raise InputError(f"{path}: spec must be the path of the spec file")
    spec_path = os.path.abspath(os.path.join(folder, obj["spec"]))
    spec = load_spec(spec_path, [s.name for s in scen])
    units = {k: p.unit for k, p in table.items()}
    units.update({ln.figure: ln.unit for ln in spec})
    return Lot(os.path.abspath(path), obj["name"], seed, parts, base, dists, chol, calibrate,
               scen, spec_path, spec, timeout, _digest(obj, scen), units, drive)
