"""The thermometer against the sample clock (tools/clock-study).

The firmware's time is the MCU crystal's: a clock fast by e ppm makes the drive resonance
read e ppm low, which the thermometer takes for warming (the tracking drive's p_eq, the
fixed drive's P: 2Q e rad either way). A calibrated part is run at rest at one ambient
with its calibration (made at some clock) and the plant's clock set to each e of a list:
the rate's mean (compensated, and not), the thermometer's move and the valid fraction over
the settled window. The run at the first clock value also gives the thermometer's
resolution: the overlapping Allan deviation of the drive frequency the firmware reads
(f_drive_hz, fractional), in K through the structure's frequency tempco kET/2 (2-32; the
tracked frequency is the resonance, test_cl_track test_thermometer_step reads a 1 K step
back within 1 %).
"""

from __future__ import annotations

import json
import os
import subprocess

import allantools
import numpy as np

from . import cli, csvlog

COLUMNS = ["rate_dps", "rate_unc_dps", "rate_valid", "p_f_deg", "f_drive_hz",
           "f_drive_true_hz", "clock_ppm"]


def scenario(path, duration_s, ambient_c, seed, cal):
    doc = {"name": "clock_study", "description": "a calibrated part at rest, one ambient",
           "mode": "closed_loop", "seed": seed, "analyses": [], "duration_s": duration_s,
           "csv_rate_hz": 100, "firmware_params": os.path.abspath(cal),
           "ambient_c": {"kind": "const", "value": ambient_c}}
    with open(path, "w", encoding="utf-8") as fh:
        json.dump(doc, fh, indent=1)
    return path


def run(sim, scen, sets, clock_ppm, work):
    """One gyro-sim run at clock_ppm: (the CSV log, the plant's parameters, the command)."""
    tag = f"clock_{clock_ppm:+g}ppm"
    csv, js = os.path.join(work, tag + ".csv"), os.path.join(work, tag + ".json")
    cmd = [sim, "--scenario", scen, "--no-analysis", "--quiet", "--csv", csv, "--json", js,
           "--set", f"plant.clock_ppm={clock_ppm:g}"]
    for s in sets:
        cmd += ["--set", s]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        msg = (r.stderr.strip() or r.stdout.strip()).splitlines()
        raise cli.InputError(f"gyro-sim exit {r.returncode}: {msg[-1] if msg else ''}")
    with open(js, encoding="utf-8") as fh:
        params = json.load(fh)["params"]
    return csvlog.read_log(csv, need=COLUMNS, purpose="the clock study"), params, " ".join(cmd)


def window_means(log, t0_s):
    m = log["t_s"] >= t0_s
    valid = log["rate_valid"][m] > 0.5
    return {"bias_dps": float(np.mean(log["rate_dps"][m][valid])) if valid.any() else None,
            "bias_unc_dps": float(np.mean(log["rate_unc_dps"][m])),
            "p_f_deg": float(np.mean(log["p_f_deg"][m])),
            "f_drive_hz": float(np.mean(log["f_drive_hz"][m])),
            "f_drive_true_hz": float(np.mean(log["f_drive_true_hz"][m])),
            "valid": float(np.mean(valid))}


def resolution(log, t0_s, ket_per_k):
    """Overlapping ADEV of the firmware's fractional drive frequency over the window, and
    the same in K of structure (kET/2 per K)."""
    m = log["t_s"] >= t0_s
    f = log["f_drive_hz"][m]
    rate = 1.0 / float(np.median(np.diff(log["t_s"][m])))
    taus, ad, _, _ = allantools.oadev(f / np.mean(f) - 1.0, rate=rate, data_type="freq",
                                      taus="decade")
    k = 0.5 * ket_per_k
    return {"tau_s": taus, "adev_frac": ad, "adev_k": ad / k,
            "ppm_per_k": k * 1e6, "rate_hz": rate}


def at_tau(res, tau_s):
    i = int(np.argmin(np.abs(np.log(res["tau_s"] / tau_s))))
    return float(res["tau_s"][i]), float(res["adev_k"][i])


def plot(res, path, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.loglog(res["tau_s"], res["adev_k"] * 1e3, "o-")
    ax.set_xlabel("averaging time tau (s)")
    ax.set_ylabel("Allan deviation of the thermometer (mK of structure)")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def table(rows, base):
    """Markdown: each clock's move against the first."""
    out = ["| plant.clock_ppm | thermometer moves | firmware f moves | compensated "
           "bias | uncompensated | valid |", "| --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        dp = r["p_f_deg"] - base["p_f_deg"]
        dfp = (r["f_drive_hz"] / base["f_drive_hz"] - 1.0) * 1e6
        b = "n/a" if r["bias_dps"] is None else f"{r['bias_dps']:+.3f} deg/s"
        out.append(f"| {r['clock_ppm']:+g} ppm | {dp:+.3f} deg | {dfp:+.2f} ppm | {b} | "
                   f"{r['bias_unc_dps']:+.3f} deg/s | {100 * r['valid']:.0f} % |")
    return "\n".join(out)
