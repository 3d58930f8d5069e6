"""Start-up transient of the drive: true amplitude and drive phase against time."""

from __future__ import annotations

import dataclasses
import os

import numpy as np

from . import plotting
from .errors import InputError

BAND = 0.01  # the 1 % band of the start-up figure (gyro-sim's lock_time_s)


@dataclasses.dataclass
class Transient:
    t_s: np.ndarray
    amp_um: np.ndarray
    phase_deg: np.ndarray | None
    phase_label: str
    final_um: float
    settle_s: float | None


def run_name(csv_path):
    """The run's name for a title: the folder for report-style trace.csv files, else
    the file's name without .csv (a title 'trace.csv' says nothing)."""
    base = os.path.splitext(os.path.basename(str(csv_path)))[0]
    if base == "trace":  # report runs: the folder names the scenario
        parent = os.path.basename(os.path.dirname(os.path.abspath(str(csv_path))))
        return parent or base
    return base


def analyse(log, t_end_s):
    t = log["t_s"]
    amp = log["drive_amp_true_m"] * 1e6
    if t[0] > 0.05 or amp[0] > 0.5 * max(float(np.max(amp)), 1e-12):
        raise InputError(f"{log.path}: does not start from power-on (t0 {t[0]:.3g} s, "
                         "drive amplitude already up)")
    # Final amplitude: the mean over the last 10 % of the whole log (the loop holds it).
    n = len(t)
    final = float(np.mean(amp[-max(1, n // 10):]))
    if final <= 0:
        raise InputError(f"{log.path}: the drive never moved (true amplitude 0)")
    outside = np.abs(amp - final) > BAND * final
    settle = None
    if not outside[-1]:
        last_out = np.nonzero(outside)[0]
        settle = float(t[last_out[-1] + 1]) if last_out.size else float(t[0])
    keep = t <= t_end_s
    if keep.sum() < 2:
        raise InputError(f"{log.path}: fewer than 2 rows before t = {t_end_s} s")
    if "drive_phase_true_deg" in log:
        phase, label = log["drive_phase_true_deg"], "true drive phase [deg]"
    elif "drive_phase_deg" in log:
        phase, label = log["drive_phase_deg"], "measured drive phase (firmware) [deg]"
    else:
        phase, label = None, ""
    return Transient(t[keep], amp[keep], None if phase is None else phase[keep], label,
                     final, settle)


def plot(res: Transient, out_path, title):
    rows = 2 if res.phase_deg is not None else 1
    fig, axes = plotting.figure(rows, 1, height_in=3.0, width_in=7.5, sharex=True)
    ax = axes[0] if rows == 2 else axes
    ax.plot(res.t_s, res.amp_um, lw=1.0, label="true drive amplitude")
    ax.axhspan(res.final_um * (1 - BAND), res.final_um * (1 + BAND), color="tab:green",
               alpha=0.2, label=f"final {res.final_um:.3f} um +-1 %")
    if res.settle_s is not None and res.settle_s <= res.t_s[-1]:
        ax.axvline(res.settle_s, color="tab:red", ls="--", lw=0.8,
                   label=f"within 1 % and held from {res.settle_s:.3f} s")
    plotting.finish(ax, title=title, ylabel="amplitude [um]",
                    xlabel=None if rows == 2 else "time since power-on [s]")
    if rows == 2:
        axes[1].plot(res.t_s, res.phase_deg, lw=1.0, color="tab:purple",
                     label=res.phase_label.replace(" [deg]", ""))
        plotting.finish(axes[1], ylabel="drive phase [deg]", xlabel="time since power-on [s]")
    d, name = os.path.split(str(out_path))
    return plotting.save(fig, d or ".", name)
