"""The lot report: yield against the spec, what spread costs it, the worst parts.

DIR/report.md with DIR/hist_*.png (each spec line's figure over the lot, its limits
drawn) and DIR/scatter_*.png (a failing line's figure against the drawn parameters that
go with it most). Yields carry a 95 % Clopper-Pearson interval (scipy's binomtest). A
line whose figure a part lacks is "not measured" for that part: left out of the line's
yield, and said so. What spread costs the yield: for each failing line, the drawn
parameters ranked by |Spearman rho| with the figure; a parameter's share of the lost
yield is estimated as sum over lines of failures x rho^2 / (sum of rho^2 of that line),
an association, not a proof of cause.

compare(): the difference of two lots' yields judged on one spec, with Newcombe's
hybrid score interval (method 10, built on the Wilson intervals of each lot).
"""

from __future__ import annotations

import json
import math
import os
import re

import numpy as np
import pandas as pd
from scipy import stats

from . import lotfile, lotjudge, plotting
from .cli import write_text
from .errors import InputError

WORST = 10
TOP_PARAMS = 3


def load_dir(out: str):
    """(table, spec lines, units) of a finished lot folder."""
    path = os.path.join(out, "lot.parquet")
    if not os.path.isfile(path):
        raise InputError(f"{out}: no lot.parquet (not a lot folder, or no part finished)")
    df = pd.read_parquet(path)
    lines = lotfile.load_spec(os.path.join(out, "spec.json"))
    try:
        with open(os.path.join(out, "units.json"), encoding="utf-8") as fh:
            units = json.load(fh)
    except (OSError, ValueError):
        units = {}
    return df, lines, units


def ci(k: int, n: int, method: str = "exact") -> tuple:
    """(yield, low, high) at 95 %; NaNs when n == 0."""
    if n == 0:
        return math.nan, math.nan, math.nan
    c = stats.binomtest(int(k), int(n)).proportion_ci(0.95, method=method)
    return k / n, c.low, c.high


def line_yields(df: pd.DataFrame, lines) -> list:
    out = []
    for ln in lines:
        col = df[f"pass.{ln.figure}"]
        n, k = int(col.notna().sum()), int((col == True).sum())  # noqa: E712  (nullable)
        out.append({"line": ln, "measured": n, "passed": k, "not_measured": len(df) - n,
                    "ci": ci(k, n)})
    return out


def params_of(df: pd.DataFrame) -> list:
    return [c for c in df.columns if c.startswith("plant.")]


def rank_params(df: pd.DataFrame, figure: str) -> list:
    """[(param, rho, p)] by |Spearman rho| with the figure, over the parts measured."""
    out = []
    sub = df[df[figure].notna()] if figure in df else df.iloc[:0]
    for p in params_of(df):
        if len(sub) < 3 or sub[p].nunique() < 2 or sub[figure].nunique() < 2:
            continue
        r = stats.spearmanr(sub[p], sub[figure])
        out.append((p, float(r.statistic), float(r.pvalue)))
    return sorted(out, key=lambda t: -abs(t[1]))


def yield_cost(df: pd.DataFrame, ylines: list) -> dict:
    """{param: parts' failures attributed} (module docstring: rho^2 shares)."""
    cost = {}
    for y in ylines:
        fails = y["measured"] - y["passed"]
        ranks = rank_params(df, y["line"].figure) if fails else []
        total = sum(r * r for _, r, _ in ranks)
        for p, r, _ in ranks:
            cost[p] = cost.get(p, 0.0) + (fails * r * r / total if total > 0 else 0.0)
    return dict(sorted(cost.items(), key=lambda kv: -kv[1]))


def _slug(figure: str) -> str:
    return re.sub(r"[^A-Za-z0-9_]+", "_", figure)


def _label(name: str, units: dict) -> str:
    u = units.get(name, "")
    return f"{name} ({u})" if u else f"{name} (-)"


def _limits(ax, ln, vertical=True):
    draw = ax.axvline if vertical else ax.axhline
    for x, what in ((ln.lo, "min"), (ln.hi, "max")):
        if x is not None:
            draw(x, color="C3", linestyle="--", label=f"spec {what} {x:g}")


def histogram(df, ln, units, out):
    v = pd.to_numeric(df.get(ln.figure, pd.Series(dtype=float)), errors="coerce").dropna()
    if v.empty:
        return None
    fig, ax = plotting.figure()
    ax.hist(v, bins=max(5, min(40, int(np.sqrt(len(v))) * 2)), color="C0", alpha=0.8)
    _limits(ax, ln)
    plotting.finish(ax, title=f"{ln.figure}: {len(v)} parts measured",
                    xlabel=_label(ln.figure, units), ylabel="parts (count)")
    return os.path.basename(plotting.save(fig, out, f"hist_{_slug(ln.figure)}.png"))


def scatter(df, ln, ranks, units, out):
    top = ranks[:TOP_PARAMS]
    if not top:
        return None
    fig, axes = plotting.figure(1, len(top), height_in=4.0, width_in=4.2 * len(top))
    axes = np.atleast_1d(axes)
    ok = df[f"pass.{ln.figure}"]
    for ax, (p, rho, _) in zip(axes, top):
        good, bad = df[ok == True], df[ok == False]  # noqa: E712  (nullable)
        ax.scatter(good[p], good[ln.figure], s=12, color="C0", label="pass")
        ax.scatter(bad[p], bad[ln.figure], s=16, color="C3", marker="x", label="fail")
        _limits(ax, ln, vertical=False)
        plotting.finish(ax, title=f"Spearman rho {rho:+.2f}", xlabel=_label(p, units),
                        ylabel=_label(ln.figure, units))
    return os.path.basename(plotting.save(fig, out, f"scatter_{_slug(ln.figure)}.png"))


def _excess(df, ln) -> pd.Series:
    """How far beyond the line each part is, relative to the limit's size."""
    v = pd.to_numeric(df.get(ln.figure, pd.Series(np.nan, index=df.index)), errors="coerce")
    e = pd.Series(-np.inf, index=df.index)
    for lim, sign in ((ln.lo, -1.0), (ln.hi, 1.0)):
        if lim is not None:
            e = np.maximum(e, sign * (v - lim) / (abs(lim) or 1.0))
    return e.fillna(-np.inf)


def worst_parts(df, lines, n=WORST) -> pd.DataFrame:
    score = pd.concat([_excess(df, ln) for ln in lines], axis=1).max(axis=1)
    order = sorted(df.index, key=lambda i: (bool(df.at[i, "pass"]), -score[i]))
    return df.loc[order[:n]]


def _commands(out: str, k: int) -> list:
    try:
        with open(os.path.join(out, "parts", f"{k:05d}", "commands.json"), encoding="utf-8") as fh:
            return json.load(fh)
    except (OSError, ValueError):
        return []


def _pct(x) -> str:
    return "n/a" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{100 * x:.1f} %"


def _yield_md(df, ylines) -> list:
    k = int(df["pass"].sum())
    p, lo, hi = ci(k, len(df))
    md = [f"Overall: **{k} of {len(df)} parts pass ({_pct(p)}, 95 % CI {_pct(lo)} .. {_pct(hi)})**, "
          "Clopper-Pearson. A part passes when its flow ran and no measured line failed.", "",
          "| spec line | measured | pass | yield | 95 % CI | not measured |", "| --- | --- | --- | --- | --- | --- |"]
    for y in ylines:
        p, lo, hi = y["ci"]
        md.append(f"| `{y['line'].text()}` | {y['measured']} | {y['passed']} | {_pct(p)} | "
                  f"{_pct(lo)} .. {_pct(hi)} | {y['not_measured']} |")
    missing = [y["line"].figure for y in ylines if y["not_measured"]]
    if missing:
        md += ["", "Not measured on some or all parts (left out of those lines' yields, never "
               f"counted as a pass): {', '.join(f'`{m}`' for m in missing)}."]
    return md + [""]


def _cost_md(df, ylines, units, out) -> list:
    md = ["## What costs the yield", ""]
    cost = yield_cost(df, ylines)
    if not cost:
        return md + ["No measured line failed.", ""]
    md += ["| drawn parameter | failures attributed (rho^2 share) |", "| --- | --- |"]
    md += [f"| `{p}` | {c:.1f} |" for p, c in cost.items() if c > 0.05]
    for y in ylines:
        if y["measured"] == y["passed"]:
            continue
        ranks = rank_params(df, y["line"].figure)
        png = scatter(df, y["line"], ranks, units, out)
        md += ["", f"`{y['line'].text()}`: {y['measured'] - y['passed']} failures; "
               + ", ".join(f"`{p}` rho {r:+.2f} (p {pv:.2g})" for p, r, pv in ranks[:TOP_PARAMS])]
        md += [f"![{y['line'].figure}]({png})"] if png else []
    return md + [""]


def _worst_md(df, lines, out) -> list:
    md = ["## Worst parts", "", "Each re-runs alone with the commands below (its folder "
          "`parts/NNNNN/` keeps the calibration and the JSON figures).", ""]
    for _, r in worst_parts(df, lines).iterrows():
        k = int(r["part"])
        md.append(f"- part {k} ({'pass' if r['pass'] else 'FAIL'}): {r['fail_reason'] or 'closest to a limit'}")
        md += ["", "  ```sh"] + [f"  {c}" for c in _commands(out, k)] + ["  ```", ""]
    return md


def _runs_md(out: str) -> list:
    try:
        with open(os.path.join(out, "runs.json"), encoding="utf-8") as fh:
            runs = json.load(fh)
    except (OSError, ValueError):
        return []
    md = ["## Runs", "", "Host facts (DIR/runs.json, DIR/timings.parquet); part-hours count the scenarios' "
          "simulated time, not the calibration's.", "",
          "| workers | parts run | wall (s) | simulated part-hours | part-hours per wall-hour |",
          "| --- | --- | --- | --- | --- |"]
    for r in runs:
        rate = r.get("part_hours_per_wall_hour")
        md.append(f"| {r.get('workers')} | {r.get('parts_run')} | {r.get('wall_s', 0):.1f} | "
                  f"{r.get('sim_s', 0) / 3600:.3g} | {'n/a' if rate is None else f'{rate:.1f}'} |")
    return md + [""]


def report(out: str, title: str = "") -> str:
    df, lines, units = load_dir(out)
    ylines = line_yields(df, lines)
    md = [f"# Lot report{': ' + title if title else ''}", "",
          f"{len(df)} parts; drawn parameters: {', '.join(f'`{p}`' for p in params_of(df))}.", "",
          "## Yield", ""] + _yield_md(df, ylines) + ["## Figures", ""]
    for ln in lines:
        png = histogram(df, ln, units, out)
        md.append(f"![{ln.figure}]({png})" if png else f"`{ln.figure}`: not measured on any part.")
    md += [""] + _cost_md(df, ylines, units, out) + _worst_md(df, lines, out) + _runs_md(out)
    return write_text(os.path.join(out, "report.md"), "\n".join(md) + "\n")


def newcombe(k1, n1, k2, n2) -> tuple:
    """(p1 - p2, low, high) at 95 %: Newcombe's hybrid score interval."""
    p1, l1, u1 = ci(k1, n1, "wilson")
    p2, l2, u2 = ci(k2, n2, "wilson")
    d = p1 - p2
    return d, d - math.hypot(p1 - l1, u2 - p2), d + math.hypot(u1 - p1, p2 - l2)


def compare(out: str, other: str) -> str:
    """DIR/compare.md: this lot's yields minus the other's, both judged on this spec."""
    a, lines, _ = load_dir(out)
    b, _, _ = load_dir(other)
    b = lotjudge.judge(b, lines)
    md = [f"# Lot comparison: `{out}` minus `{other}`", "",
          "Both judged on the spec of the first; 95 % CI by Newcombe's hybrid score method.", "",
          "| line | first: pass / measured | second: pass / measured | difference | 95 % CI |",
          "| --- | --- | --- | --- | --- |"]
    rows = [("overall", int(a["pass"].sum()), len(a), int(b["pass"].sum()), len(b))]
    for ya, yb in zip(line_yields(a, lines), line_yields(b, lines)):
        rows.append((f"`{ya['line'].text()}`", ya["passed"], ya["measured"], yb["passed"], yb["measured"]))
    for name, k1, n1, k2, n2 in rows:
        d, lo, hi = newcombe(k1, n1, k2, n2) if n1 and n2 else (math.nan,) * 3
        md.append(f"| {name} | {k1} / {n1} | {k2} / {n2} | {_pct(d)} | {_pct(lo)} .. {_pct(hi)} |")
    write_text(os.path.join(out, "compare.md"), "\n".join(md) + "\n")
    return "\n".join(md)
