"""Shared matplotlib helpers. The Agg backend is forced: the tools run on build machines
and over SSH, never with a display, and write PNG files only."""

from __future__ import annotations

import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (backend must be chosen first)

from .errors import InputError  # noqa: E402

DPI = 120


def figure(nrows=1, ncols=1, height_in=4.5, width_in=7.0, sharex=False, height_ratios=None):
    """A new figure and its axes (a single Axes when nrows == ncols == 1); height_ratios
    shares the rows' total height (height_in x nrows) unevenly (a 0/1 flag under a
    signal needs less)."""
    kw = {"height_ratios": height_ratios} if height_ratios else {}
    fig, axes = plt.subplots(nrows, ncols, figsize=(width_in, height_in * nrows),
                             sharex=sharex, squeeze=True, gridspec_kw=kw)
    return fig, axes


def finish(ax, title=None, xlabel=None, ylabel=None, legend=True):
    """Grid, labels and legend in the house style."""
    if title:
        ax.set_title(title, fontsize=10)
    if xlabel:
        ax.set_xlabel(xlabel)
    if ylabel:
        ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    if legend and ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8)


def save(fig, out_dir, name):
    """Write fig to out_dir/name (PNG), close it, and return the path."""
    path = os.path.join(out_dir, name)
    fig.tight_layout()
    try:
        fig.savefig(path, dpi=DPI)
    except OSError as e:
        raise InputError(f"{path}: cannot write ({e.strerror})") from None
    finally:
        plt.close(fig)
    return path
