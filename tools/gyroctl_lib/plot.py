"""`gyroctl plot`: a CSV log (gyroctl log, gyro-sim) drawn as one panel per column, each
labelled with its unit, over an optional time window."""

from __future__ import annotations

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from gyrotools import fields  # noqa: E402  (tools/ holds both packages)

MAX_DEFAULT_PANELS = 8  # beyond this a figure is too tall to read; --columns chooses


class PlotError(Exception):
    pass


def read_csv(path):
    """Header names and columns (lists of floats; 0x... read as integers)."""
    try:
        fh = open(path, "r", encoding="utf-8-sig")
    except OSError as e:
        raise PlotError(f"{path}: cannot open ({e.strerror})") from None
    header, cols = None, None
    with fh:
        for lineno, line in enumerate(fh, start=1):
            s = line.strip()
            if not s or s.startswith("#"):
                continue
            cells = [c.strip() for c in s.split(",")]
            if header is None:
                header = cells
                cols = [[] for _ in header]
                continue
            if len(cells) != len(header):
                raise PlotError(f"{path}:{lineno}: {len(cells)} fields, header has {len(header)}")
            for c, v in zip(cols, cells):
                try:
                    c.append(float(int(v, 16)) if v.lower().startswith("0x") else float(v))
                except ValueError:
                    raise PlotError(f"{path}:{lineno}: not a number: {v!r}") from None
    if header is None or not cols or not cols[0]:
        raise PlotError(f"{path}: no data")
    return header, cols


def _choose(header, columns, path):
    """Indices of the columns to draw: those named (telemetry or gyro-sim names), or
    every column but time, at most MAX_DEFAULT_PANELS."""
    rest = [i for i, h in enumerate(header) if h != "t_s"]
    if not columns:
        if len(rest) > MAX_DEFAULT_PANELS:
            print(f"gyroctl: plot: {len(rest)} columns; drawing the first {MAX_DEFAULT_PANELS} "
                  "(choose with --columns)", file=sys.stderr)
        return rest[:MAX_DEFAULT_PANELS]
    out = []
    for c in columns:
        name = c if c in header else fields.ALIASES.get(c)
        if name not in header:
            raise PlotError(f"{path}: no column '{c}'; it has: {', '.join(header)}")
        out.append(header.index(name))
    return out


def _window(t, t_start, t_end, path):
    keep = [i for i, x in enumerate(t) if (t_start is None or x >= t_start)
            and (t_end is None or x <= t_end)]
    if len(keep) < 2:
        raise PlotError(f"{path}: fewer than 2 rows between t = {t_start} and {t_end} s")
    return keep


def _title(csv_path, t):
    base = os.path.splitext(os.path.basename(str(csv_path)))[0]
    if base == "trace":  # report runs: the folder names the scenario
        base = os.path.basename(os.path.dirname(os.path.abspath(str(csv_path)))) or base
    return f"{base}: t = {t[0]:.3f} to {t[-1]:.3f} s"


def plot(csv_path, out_path=None, columns=None, t_start=None, t_end=None):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    header, cols = read_csv(csv_path)
    if "t_s" in header:
        t_all, xlabel = cols[header.index("t_s")], "t [s]"
    else:
        if t_start is not None or t_end is not None:
            raise PlotError(f"{csv_path}: no t_s column for --t-start/--t-end")
        t_all, xlabel = [float(i) for i in range(len(cols[0]))], "row"
    panels = _choose(header, columns, csv_path)
    if not panels:
        raise PlotError(f"{csv_path}: nothing to plot besides time")
    keep = _window(t_all, t_start, t_end, csv_path)
    t = [t_all[i] for i in keep]
    fig, axes = plt.subplots(len(panels), 1, sharex=True, squeeze=False,
                             figsize=(8, 1.2 + 1.9 * len(panels)))
    for ax, i in zip(axes[:, 0], panels):
        ax.plot(t, [cols[i][k] for k in keep], lw=0.8)
        ax.set_ylabel(fields.axis_label(header[i]), fontsize=8)
        ax.grid(True, alpha=0.3)
    axes[-1, 0].set_xlabel(xlabel)
    axes[0, 0].set_title(_title(csv_path, t), fontsize=10)
    fig.tight_layout()
    out = out_path or os.path.splitext(str(csv_path))[0] + ".png"
    try:
        fig.savefig(out, dpi=100)
    except OSError as e:
        raise PlotError(f"{out}: cannot write ({e.strerror})") from None
    finally:
        plt.close(fig)
    return out
