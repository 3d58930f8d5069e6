"""A lot's table judged against its spec: pass/fail per line, per part, and why.

Each spec line gives a column pass.FIGURE: True, False, or missing (NA) when the part has
no value for the figure ("not measured": neither a pass nor a fail, and not counted in
that line's yield). A part passes when its flow ran without error and no measured line
failed; fail_reason lists what failed, the flow's error first.
"""

from __future__ import annotations

import numpy as np
import pandas as pd


def line_pass(values: pd.Series, line) -> pd.Series:
    """True/False/NA of one spec line over a column of values."""
    v = pd.to_numeric(values, errors="coerce")
    ok = pd.Series(True, index=v.index)
    if line.lo is not None:
        ok &= v >= line.lo
    if line.hi is not None:
        ok &= v <= line.hi
    return ok.astype("boolean").mask(v.isna())


def _fail_text(line, x) -> str:
    if line.lo is not None and x < line.lo:
        return f"{line.figure} {x:.4g} < {line.lo:g}"
    return f"{line.figure} {x:.4g} > {line.hi:g}"


def _failed(v) -> bool:
    return v is not pd.NA and not bool(v)


def judge(df: pd.DataFrame, lines) -> pd.DataFrame:
    """df with pass.FIGURE per line, pass and fail_reason (the previous ones replaced)."""
    df = df.drop(columns=[c for c in df.columns if c.startswith("pass.")] + ["pass", "fail_reason"],
                 errors="ignore").copy()
    nan = pd.Series(np.nan, index=df.index)
    cols = {}
    for ln in lines:
        cols[f"pass.{ln.figure}"] = line_pass(df[ln.figure] if ln.figure in df else nan, ln)
    flow = df["flow_error"].fillna("") if "flow_error" in df else pd.Series("", index=df.index)
    reasons, passed = [], []
    for i in df.index:
        why = [flow[i]] if flow[i] else []
        why += [_fail_text(ln, float(df.at[i, ln.figure])) for ln in lines
                if _failed(cols[f"pass.{ln.figure}"][i])]
        reasons.append("; ".join(why))
        passed.append(not why)
    extra = pd.DataFrame(cols, index=df.index)
    extra["pass"] = passed
    extra["fail_reason"] = reasons
    return pd.concat([df, extra], axis=1)
