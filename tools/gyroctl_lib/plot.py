"""`gyroctl plot`: a CSV log (gyroctl log, gyro-sim) drawn as one panel per column."""

from __future__ import annotations

import os


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


def plot(csv_path, out_path=None):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    header, cols = read_csv(csv_path)
    if "t_s" in header:
        ti = header.index("t_s")
        t, xlabel = cols[ti], "t [s]"
    else:
        ti, t, xlabel = None, list(range(len(cols[0]))), "row"
    panels = [i for i in range(len(header)) if i != ti]
    if not panels:
        raise PlotError(f"{csv_path}: nothing to plot besides time")
    fig, axes = plt.subplots(len(panels), 1, sharex=True, squeeze=False,
                             figsize=(9, 1.6 + 1.5 * len(panels)))
    for ax, i in zip(axes[:, 0], panels):
        ax.plot(t, cols[i], lw=0.8)
        ax.set_ylabel(header[i], fontsize=8)
        ax.grid(True, alpha=0.3)
    axes[-1, 0].set_xlabel(xlabel)
    fig.suptitle(os.path.basename(str(csv_path)))
    fig.tight_layout()
    out = out_path or os.path.splitext(str(csv_path))[0] + ".png"
    fig.savefig(out, dpi=100)
    plt.close(fig)
    return out
