"""The figures of the IEEE 1431 report (gyrotools/ieee1431.py): one PNG per series in
DIR/ieee1431/, units on every axis, the part, the series and its seed in the title, the
tools/calibrate command that made the runs under it."""

from __future__ import annotations

import textwrap

import numpy as np

from . import allan, plotting, scalefactor, thermcal

WRAP = 95  # characters of the command per title line (a 7 in figure at 10 pt)


def title(ctx, what, run):
    """What the figure shows; the part and the run's seed; the command, wrapped."""
    cmd = ctx.report.get("command") or ""
    return "\n".join([what, f"{ctx.part()}, seed {run.get('seed')}"]
                      + textwrap.wrap(cmd, WRAP, break_on_hyphens=False))


def _mark(axes, t, label, color):
    """A vertical line at time t on every axes, labelled on the first."""
    if t is None:
        return
    for k, ax in enumerate(axes):
        ax.axvline(t, color=color, ls="--", lw=0.9, label=label if k == 0 else None)


def turn_on(ctx, log, mask, figs, run):
    """The output and rate_valid over the first seconds after power-on."""
    t, out, truth = log["t_s"][mask], log["rate_dps"][mask], log["rate_true_dps"][mask]
    b = figs["error_bound_dps"]
    fig, (a1, a2) = plotting.figure(2, 1, height_in=3.0, sharex=True, height_ratios=(3, 1))
    a1.fill_between(t, truth - b, truth + b, color="C2", alpha=0.2,
                    label=f"true rate +-{b:g} deg/s (the verification's error bound)")
    a1.plot(t, out, lw=0.8, color="C0", label="rate_dps (output, valid or not)")
    a1.plot(t, truth, "--", lw=0.8, color="k", label="rate_true_dps (input)")
    a2.step(t, log["rate_valid"][mask], where="post", lw=0.9, color="C0", label="rate_valid")
    on, within = figs["turn_on_time_s"], figs["time_to_error_bound_s"]
    _mark((a1, a2), on, "turn-on time " + ("n/a" if on is None else f"{on:.3g} s"), "C3")
    _mark((a1, a2), within, "within the bound " + ("n/a" if within is None
                                                   else f"{within:.3g} s"), "C1")
    plotting.finish(a1, title=title(ctx, "Turn-on (IEEE 1431 12.5)", run),
                    ylabel="rate [deg/s]")
    a2.set_ylim(-0.1, 1.1)
    plotting.finish(a2, xlabel="time since power-on [s]", ylabel="rate_valid [0/1]")
    return plotting.save(fig, ctx.folder, "turn_on.png")


def warm_up(ctx, log, figs, run):
    """A cold start's 1 s means, compensated and raw, against the time since power-on (a
    log axis: the compensated output warms in seconds, the raw one in many minutes), with
    the bound and both settling times; the structure's temperature under them."""
    m = thermcal.warmup_means(log)
    t, b = m["t_s"] + 0.5 * thermcal.BIN_S, figs["bound_dps"]
    fig, (a1, a2) = plotting.figure(2, 1, height_in=3.2, sharex=True, height_ratios=(3, 1))
    a1.axhspan(-b, b, color="C2", alpha=0.2, label=f"input +-{b:g} deg/s")
    a1.plot(t, m["rate_dps"], lw=0.9, color="C0", label="rate_dps (compensated, valid samples)")
    a1.plot(t, m["rate_unc_dps"] - figs["raw_final_dps"], lw=0.9, color="C7",
            label=f"rate_unc_dps less its final level {figs['raw_final_dps']:+.3f} deg/s")
    for key, what, color in (("warmup_time_s", "warm-up time", "C3"),
                             ("warmup_time_avg_s",
                              f"warm-up time ({figs.get('warmup_avg_s', 0):g} s means)", "C5"),
                             ("raw_settle_time_s", "raw output settled", "C1")):
        if key not in figs:  # a report made before the averaged figure
            continue
        _mark((a1, a2), figs[key], what + (" n/a" if figs[key] is None else f" {figs[key]:.0f} s"),
              color)
    a1.set_xscale("log")
    a1.set_xlim(0.5 * thermcal.BIN_S, t[-1])
    plotting.finish(a1, title=title(ctx, f"Warm-up from a cold start at {figs['ambient_c']:g} "
                                         "degC (IEEE 1431 12.6)", run),
                    ylabel="1 s mean of the rate [deg/s]")
    late = log["t_s"] >= 0.5 * thermcal.BIN_S
    for col, color, name in (("t_struct_c", "C1", "structure"), ("t_circuit_c", "C4", "circuit"),
                             ("t_ambient_c", "C7", "ambient")):
        if col in log:
            a2.plot(log["t_s"][late], log[col][late], lw=0.9, color=color, label=name + " (logged)")
    plotting.finish(a2, xlabel="time since power-on [s]", ylabel="temperature [degC]")
    return plotting.save(fig, ctx.folder, "warm_up.png")


def scale_factor(ctx, res, run):
    """scalefactor.plot's figure (output against input, input-referred residuals)."""
    what = (f"Scale factor (IEEE 1431 12.9): SF {(res.sf - 1.0) * 1e6:+.0f} ppm, asymmetry "
            f"{res.asymmetry * 1e6:+.0f} ppm")
    return scalefactor.plot(res, ctx.folder, "scale_factor.png", title=title(ctx, what, run))


def _coefficient(entry):
    """An IEEE 952 coefficient as the legend shows it: its value and unit, or n/a."""
    return "n/a" if entry["value"] is None else f"{entry['value']:.3g} {entry['unit']}"


def ieee952_label(ieee, what):
    return f"IEEE 952 ({what}): " + ", ".join(f"{k} {_coefficient(ieee[k])}" for k in "NBKR")


def drift(ctx, res, means, run):
    """The 1 s means against time and the Allan deviations, compensated and not; the
    compensated output's fit and IEEE 952 coefficients."""
    fig, (a1, a2) = plotting.figure(2, 1, height_in=4.0)
    a1.plot(means["t_s"], means["rate_dps"], lw=0.8, color="C0", label="rate_dps (compensated)")
    a1.plot(means["t_s"], means["rate_unc_dps"], lw=0.8, color="C7",
            label="rate_unc_dps (uncompensated)")
    plotting.finish(a1, title=title(ctx, "Drift rate (IEEE 1431 12.11)", run),
                    xlabel="time since power-on [s]", ylabel="1 s mean of the rate [deg/s]")
    comp, unc = res["rate_dps"], res["rate_unc_dps"]
    allan.draw(a2, comp, what="rate_dps")
    allan.draw_points(a2, unc, "C7", "rate_unc_dps")
    a2.plot([], [], " ", label=ieee952_label(allan.ieee952(comp), "rate_dps"))
    lo = min(comp.curve.adev_dph.min(), unc.curve.adev_dph.min())
    hi = max(comp.curve.adev_dph.max(), unc.curve.adev_dph.max())
    # Room below the curves for the legend's many lines (the curves fill the top).
    a2.set_ylim(lo / 12, hi * 2)
    plotting.finish(a2, xlabel="averaging time tau [s]", ylabel="Allan deviation [deg/h]",
                    legend=False)
    a2.legend(fontsize=7, loc="lower left")
    return plotting.save(fig, ctx.folder, "drift.png")


def _unavailable(ax, entry):
    ax.text(0.5, 0.5, "\n".join(textwrap.wrap("not available: " + entry["error"], 80)),
            transform=ax.transAxes, ha="center", va="center", fontsize=8, color="C3")


def _plateau_panel(ax, pl, key, unit, limit):
    """One plateau figure against the ambient and the structure's temperature, with the
    verification's limits."""
    rows = pl["plateaus"]
    amb = [r["ambient_c"] for r in rows]
    st = [r["t_struct_c"] for r in rows]
    y = [r[key] for r in rows]
    ax.plot(amb, y, "o", color="C0", label="against the ambient (chamber)")
    if np.all(np.isfinite(st)):
        ax.plot(st, y, "s", color="C1", label="against the structure (logged)")
    for s in (-1, 1):
        ax.axhline(s * limit, color="C3", ls="--", lw=0.8,
                   label=f"limit +-{limit:g} {unit}" if s > 0 else None)


def _ramp_panel(ax, rp):
    """The 1 s means against each logged temperature, and the fitted slope against the
    one the JSON reports it for (the structure's when logged)."""
    m = rp["means_1s"]
    for col, color, name in (("t_ambient_c", "C0", "the ambient (held at the end after "
                                                    "the ramp)"),
                             ("t_struct_c", "C1", "the structure")):
        if col in m:
            ax.plot(m[col], m["rate_dps"], ".", ms=2, color=color, label=f"1 s means against {name}")
    key = next(k for k in rp if k.startswith("bias_slope_dps_per_k_of_"))
    struct = key.endswith("struct")
    x = m["t_struct_c" if struct else "t_ambient_c"]
    if np.isfinite(rp[key]):
        xx = np.array([x.min(), x.max()])
        b = np.mean(m["rate_dps"]) - rp[key] * np.mean(x)
        ax.plot(xx, b + rp[key] * xx, "-", color="k", lw=1,
                label=f"least squares: {rp[key]:+.4f} deg/s per K of the "
                      + ("structure" if struct else "ambient"))


def temperature(ctx, pl, rp):
    """Plateau bias and scale factor, and the ramp's 1 s bias means, against temperature."""
    run = {"seed": ", ".join(f"{x['seed']} ({what})" for x, what in ((pl, "plateaus"), (rp, "ramp"))
                             if "seed" in x)}
    fig, (a1, a2, a3) = plotting.figure(3, 1, height_in=2.8)
    if "error" in pl:
        _unavailable(a1, pl)
        _unavailable(a2, pl)
    else:
        _plateau_panel(a1, pl, "bias_dps", "deg/s", pl["limits"]["bias_dps"])
        _plateau_panel(a2, pl, "scale_factor_error_ppm", "ppm", pl["limits"]["scale_factor_ppm"])
    plotting.finish(a1, title=title(ctx, "Operating temperature (IEEE 1431 12.8)", run)
                    + "\nverification plateaus: bias at rest", xlabel="temperature [degC]",
                    ylabel="bias [deg/s]")
    plotting.finish(a2, title="verification plateaus: scale factor (+-100 deg/s)",
                    xlabel="temperature [degC]", ylabel="scale factor error [ppm]")
    if "error" in rp:
        _unavailable(a3, rp)
        what = "ramp"
    else:
        _ramp_panel(a3, rp)
        what = (f"ramp {rp['from_c']:g} -> {rp['to_c']:g} degC at {rp['k_per_min']:g} K/min: "
                f"1 s bias means, {rp['bias_1s_std_dps']:.3f} deg/s std")
    plotting.finish(a3, title=what, xlabel="temperature [degC]", ylabel="bias [deg/s]")
    return plotting.save(fig, ctx.folder, "temperature.png")
