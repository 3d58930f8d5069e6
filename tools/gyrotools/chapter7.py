"""The chapter-7 report's figures with their conditions (tools/report).

Every figure of the report's table says on which part it was measured (and with which
calibration file), whether the rate it comes from is compensated by that calibration,
and whether it is in or out of sample: out of sample is a run whose profile and noise
seed the calibration never saw; in sample is a fit's own residual, or a run on a profile
the calibration was fitted on. The flow's verification figures (tools/calibrate) are
read from the report.json committed beside each part's calibration.

Paths: the report runs its simulations from the report folder, so every path it writes
(figures.json, the analyses' JSON) is relative to that folder; `relative()` turns any
absolute path left in a JSON document into one.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import os

import numpy as np

# Parts: the folder under host_sim/parts holding calibration.json and the flow's
# report.json, and the plant settings that make the part in gyro-sim.
PARTS = {
    "default": {"dir": "host_sim/parts/default", "set": []},
    "ideal": {"dir": "host_sim/parts/ideal", "set": ["plant.preset=ideal"]},
    "f1300_q200": {"dir": "host_sim/parts/f1300_q200",
                   "set": ["plant.f_drive_hz=1300", "plant.q_drive=200"]},
}
# The flow's noise seeds are --seed + 100.. (rate table), +150 (linearity), +200
# (chamber), +1000.. (verification); no shipped scenario uses them.
RATE_TABLE_NOTE = ("in sample: the flow's rate-table stage fitted the scale on this profile "
                   "(seeds 101-103); this run's seed is 2")
OUT = "out of sample"
FIT_NOTE = "in sample (fit residual): fitted and judged on this run"
NA_OPEN = "n/a (open loop, no calibration)"
NA_DRIVE = "n/a (drive loop, not the rate)"
LEGEND = ("Conditions of each figure: *part* is the simulated part and the calibration the firmware "
          "ran from (a part's calibration is made by its own run of the flow, `tools/calibrate --sim`); "
          "*compensated* says whether the figure is of the rate output the calibration's temperature "
          "compensation corrects (`rate_dps`) or of the raw one (`rate_unc_dps`); *sample* is *out of "
          "sample* when the run's profile and noise seed are ones the calibration never saw, *in sample* "
          "when the figure is a fit's residual on its own data or the calibration was fitted on the "
          "run's profile.")
SETTLE_S = 30.0   # the chamber's 1 s means start after the compensation's filters settle


@dataclasses.dataclass
class Row:
    figure: str
    value: str
    thesis: str
    part: str          # a key of PARTS, or "" for the plant without a calibration
    compensated: str   # yes / no / n/a (why)
    sample: str        # out of sample / in sample (why) / n/a (why)
    source: str        # scenario name or the command that made the figure


def fmt(x, nd=4):
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "n/a"
    return f"{x:.{nd}g}"


def figure(F, scen, key, nd=4):
    """Scenario scen's figure key from the campaign's figures F, formatted (fmt)."""
    return fmt(F[scen].get(key), nd)


def part_cell(part, open_loop=False):
    if open_loop:
        return "default plant, no calibration"
    return f"{part} (`{PARTS[part]['dir']}/calibration.json`)"


def sim_args(part, root):
    """gyro-sim arguments that make `part` and load its calibration; root: the
    repository as seen from where gyro-sim runs."""
    args = []
    for s in PARTS[part]["set"]:
        args += ["--set", s]
    return args + ["--firmware-params", os.path.join(root, PARTS[part]["dir"], "calibration.json")]


def parts_doc(root):
    return {k: {"calibration": os.path.join(root, p["dir"], "calibration.json"),
                "flow_report": os.path.join(root, p["dir"], "report.json"), "set": p["set"]}
            for k, p in PARTS.items()}


def check_parts(rows, runs, root):
    """Each row's part is the calibration its run loaded (gyro-sim's firmware_params)."""
    for r in rows:
        run = runs.get(r.source)
        if run is None:
            continue
        want = os.path.normpath(os.path.join(root, PARTS[r.part]["dir"], "calibration.json")) if r.part else None
        if run["calibration"] != want:
            raise ValueError(f"{r.source}: the run loaded {run['calibration']}, the table says {want}")


def one_s_means(t, y, t_from, t_to=None):
    """Means of y over the whole 1 s bins from t_from (to t_to): the thesis's fig. 7-17."""
    m = (t >= t_from) & (t < (t_to if t_to is not None else np.inf)) & np.isfinite(y)
    if not m.any():
        return np.array([])
    nb = int((t[m][-1] - t_from) // 1.0)   # the last, partial bin is left out
    k = np.floor(t[m] - t_from).astype(int)
    keep = k < nb
    n = np.bincount(k[keep], minlength=nb)
    s = np.bincount(k[keep], weights=y[m][keep], minlength=nb)
    return s[n > 0] / n[n > 0]


def means_stats(trace, column, t_from, t_to=None):
    """std and p-p of the 1 s means of a trace column, and the valid fraction there."""
    mu = one_s_means(trace["t_s"], trace[column], t_from, t_to)
    m = trace["t_s"] >= t_from
    valid = float(np.mean(trace["rate_valid"][m] > 0.5)) if np.any(m) else None
    if mu.size < 2:
        return {"std_dps": None, "pp_dps": None, "seconds": int(mu.size), "valid_fraction": valid}
    return {"std_dps": float(np.std(mu)), "pp_dps": float(np.ptp(mu)), "mean_dps": float(np.mean(mu)),
            "seconds": int(mu.size), "t_from_s": t_from, "valid_fraction": valid}


def cooldown_start(scenario):
    a = scenario["ambient_c"]
    return a["t_start_s"] + a["heat_s"]


def verification(doc):
    """The out-of-sample figures of a part's calibration flow (its report.json)."""
    v = doc["verify"]
    r, pl, ramp, nz = v["rate"], v["thermal_plateaus"]["plateaus"], v["thermal_ramp"], v["noise"]
    tr = v.get("thermal_transient")  # a calibration verified before the transient had none
    wu = v.get("warmup")  # nor the warm-up
    return {
        "command": doc["command"],
        "seeds": [r["seed"], v["thermal_plateaus"]["seed"], ramp["seed"], nz["seed"]],
        "sf_ppm": r["scale_factor_ppm"], "subrange_worst_ppm": r["subrange_worst"]["slope_ppm"],
        "bias_at_rest_dps": r["bias_at_rest_dps"], "worst_valid_error_dps": r["worst_valid_error_dps"],
        "plateaus_c": [p["ambient_c"] for p in pl],
        "plateau_bias_dps": [min(p["bias_dps"] for p in pl), max(p["bias_dps"] for p in pl)],
        "plateau_sf_ppm": [min(p["sf_ppm"] for p in pl), max(p["sf_ppm"] for p in pl)],
        "ramp_std_dps": ramp["bias_1s_std_dps"], "ramp_max_dps": ramp["bias_1s_max_abs_dps"],
        "ramp_valid": ramp["valid_fraction"], "ramp_k_per_min": ramp["k_per_min"],
        "ramp_c": [ramp["from_c"], ramp["to_c"]],
        "noise_ratio_1s": nz["ratio"], "noise_ratio_10s": nz["ratio_10s"],
        "transient": None if tr is None else {
            k: tr[k] for k in ("base_c", "hot_c", "heat_s", "bias_1s_std_dps", "bias_1s_pp_dps",
                               "valid_fraction", "seed")},
        "warmup": None if wu is None else {
            k: wu[k] for k in ("ambient_c", "bound_dps", "warmup_time_s", "raw_settle_time_s",
                               "raw_change_dps", "worst_valid_1s_dps", "seed")},
        "passed": bool(r["passed"] and v["thermal_plateaus"]["ok"] and ramp["ok"] and nz["ok"]
                       and (tr is None or tr["ok"]) and (wu is None or wu["ok"])),
    }


def verification_rows(part, vf):
    src = f"`{vf['command']}` (verification seeds {', '.join(str(s) for s in vf['seeds'])}; " \
          f"`{PARTS[part]['dir']}/report.json`)"
    pc = ", ".join(f"{c:g}" for c in vf["plateaus_c"])
    rows = [
        ("flow verification: scale factor (+-20..160) / worst sub-range slope / bias at rest",
         f"{vf['sf_ppm']:+.0f} ppm / {vf['subrange_worst_ppm']:+.0f} ppm / {vf['bias_at_rest_dps']:+.3f} deg/s",
         ""),
        (f"flow verification: unseen plateaus {pc} degC: bias / scale factor",
         f"{vf['plateau_bias_dps'][0]:+.3f}..{vf['plateau_bias_dps'][1]:+.3f} deg/s / "
         f"{vf['plateau_sf_ppm'][0]:+.0f}..{vf['plateau_sf_ppm'][1]:+.0f} ppm", ""),
        (f"flow verification: ramp {vf['ramp_c'][0]:g} -> {vf['ramp_c'][1]:g} degC at "
         f"{vf['ramp_k_per_min']:g} K/min, 1 s means of the bias: std (max)",
         f"{fmt(vf['ramp_std_dps'], 2)} deg/s ({fmt(vf['ramp_max_dps'], 2)}), valid "
         f"{100 * vf['ramp_valid']:.1f} %", "0.462 deg/s over its cool-down (in sample)"),
        ("flow verification: Allan deviation compensated / not, at 1 s and 10 s",
         f"{vf['noise_ratio_1s']:.2f}x / {vf['noise_ratio_10s']:.2f}x", ""),
    ]
    tr = vf.get("transient")
    if tr is not None:
        rows.append((f"flow verification: transient {tr['base_c']:g} -> {tr['hot_c']:g} degC "
                     f"for {tr['heat_s']:g} s and back (seed {tr['seed']}), 1 s means of the "
                     "bias: std (p-p)",
                     f"{fmt(tr['bias_1s_std_dps'], 2)} deg/s ({fmt(tr['bias_1s_pp_dps'], 2)}), "
                     f"valid {100 * tr['valid_fraction']:.1f} %",
                     "0.462 deg/s over its cool-down (in sample)"))
    wu = vf.get("warmup")
    if wu is not None:
        rows.append((f"flow verification: warm-up from a cold start at {wu['ambient_c']:g} degC "
                     f"(seed {wu['seed']}; IEEE 1431 12.6): 1 s means of the bias within "
                     f"{wu['bound_dps']:g} deg/s for good; the raw output's own settling",
                     f"{_secs(wu['warmup_time_s'])}; raw "
                     f"{_secs(wu['raw_settle_time_s'], 'not within the run')} "
                     f"(moves {wu['raw_change_dps']:+.2f} deg/s); worst valid 1 s mean "
                     f"{fmt(wu['worst_valid_1s_dps'], 2)} deg/s", ""))
    return [Row(f, v, t, part, "yes", OUT, src) for f, v, t in rows]


def _secs(t_s, none="never"):
    return none if t_s is None else f"{t_s:.0f} s"


def drive_rows(F):
    v = functools.partial(figure, F)
    sq_amp = fmt(F["square_law"]["square_law"][-1]["amp_v"])
    op = ("", "n/a", NA_OPEN)
    return [
        Row("drive resonance (sweep, `gyro-freqresp`)", f"{v('sweep', 'f0_hz', 7)} Hz", "1489.90 Hz",
            *op, "sweep"),
        Row("drive Q", v("sweep", "q"), "33.33", *op, "sweep"),
        Row("phase at resonance", f"{v('sweep', 'phase_at_f0_deg')} deg", "-99.56 deg", *op, "sweep"),
        Row("square law: amplitude at 12.75 V / nonlinearity (RMS residual of a line with "
            "intercept over the largest amplitude, the thesis's method)",
            f"{sq_amp} V / {v('square_law', 'square_law_nonlinearity_rms_pct', 2)} %",
            "0.8754 V / 0.25 %", *op, "square_law"),
        Row("drive lock (amplitude within 1 %, held)",
            f"{v('startup', 'lock_time_s', 3)} s, overshoot {v('startup', 'overshoot_pct', 2)} %",
            "about 0.2 s, with overshoot", "default", "n/a", NA_DRIVE, "startup"),
    ]


def rate_rows(F):
    v = functools.partial(figure, F)
    return [
        Row("scale factor / nonlinearity (+-160 deg/s): digital output; analog output (a meter "
            "on the DAC, as the thesis measured)",
            f"{v('rate_table', 'scale_factor', 7)} / {v('rate_table', 'nonlinearity_pct', 3)} % FS; "
            f"{v('rate_table', 'aout_scale_factor_v_per_dps', 5)} V/(deg/s) / "
            f"{v('rate_table', 'aout_nonlinearity_pct', 3)} % FS",
            "7.25 mV/(deg/s) / 0.348 % FS (0.06 % without the table's resonance points)",
            "default", "yes", RATE_TABLE_NOTE, "rate_table"),
        Row("rate noise vs Brownian floor (4-24), two-sided N",
            f"{v('brownian_only', 'arw_coeff_dph_rthz')} vs "
            f"{v('brownian_only', 'brownian_floor_dph_rthz')} deg/h/rtHz",
            "floor 18.0 at 1489.9 Hz; measured 26.4 one-sided (N 18.7)", "ideal", "yes", OUT, "brownian_only"),
        Row("all noise: ARW (fit) / lowest Allan deviation",
            f"{v('static_allan', 'arw_deg_rth')} deg/rt(h) / {v('static_allan', 'adev_min_dph')} deg/h",
            "", "default", "yes", OUT, "static_allan"),
        Row("all noise, not compensated (rate_unc_dps): lowest Allan deviation (at tau)",
            f"{v('static_allan', 'unc_adev_min_dph')} deg/h "
            f"({v('static_allan', 'unc_tau_at_adev_min_s', 3)} s)",
            "bias stability 31.3 deg/h (not compensated), rate ramp 4.30 deg/s/h from the "
            "board's warm-up", "default", "no", "n/a (no compensation)", "static_allan"),
        Row("drive-amplitude noise 1-10 Hz: half-frequency / DC+AC",
            f"{v('drive_noise_halffreq', 'drive_amp_noise_lf_rel', 3)} / "
            f"{v('drive_noise_dcac', 'drive_amp_noise_lf_rel', 3)} /rtHz",
            "half-frequency 1/2 to 2/3 lower", "default", "n/a", NA_DRIVE, "drive_noise_*"),
    ]


def thermal_rows(F, D):
    v = functools.partial(figure, F)

    def st(d):
        return (f"{fmt(d['std_dps'])} deg/s std, {fmt(d['pp_dps'])} p-p"
                + (f", valid {100 * d['valid_fraction']:.1f} %" if d.get("valid_fraction") is not None else ""))
    return [
        Row("chamber: residual bias after a fit in P / in board temperature (rate_unc_dps)",
            f"{v('temp_chamber', 'residual_bias_p_dps')} / {v('temp_chamber', 'residual_bias_sensor_dps')} deg/s",
            "bias linear in P: B = 34.59 P + 58.53", "default", "no", FIT_NOTE, "temp_chamber"),
        Row("chamber 26/28/30/35 degC, compensated by the part's calibration (1 s means)",
            st(D["chamber_comp"]), "", "default", "yes", OUT, "temp_chamber"),
        Row("cool-down fit: residual with P / with the board sensor (rate_unc_dps)",
            f"{v('cooldown', 'residual_bias_p_dps')} / {v('cooldown', 'residual_bias_sensor_dps')} deg/s",
            "", "default", "no", FIT_NOTE, "cooldown"),
        Row("cool-down, not compensated (rate_unc_dps, 1 s means)", st(D["cooldown_unc"]), "",
            "default", "no", "n/a (no compensation)", "cooldown"),
        Row("cool-down, compensated by the part's calibration (chamber plateaus, never this run; 1 s means)",
            st(D["cooldown_comp"]), "0.462 deg/s over 36.2-62.4 degC (its own fit: in sample)",
            "default", "yes", OUT, "cooldown"),
    ]


def bench_row(F):
    s = F["startup"]
    if "isr_instructions_per_tick" not in s:
        return []
    return [Row("sample interrupt on the Cortex-M4F (`tools/bench/run-bench`): "
                "instructions / cycles per tick, mean (worst)",
                f"{fmt(s['isr_instructions_per_tick'])} ({fmt(s.get('isr_instructions_per_tick_max'))}) / "
                f"{fmt(s.get('isr_cycles_est_mean'))} ({fmt(s.get('isr_cycles_est_max'))})",
                "goal <= 600 instructions, 672 cycles", "default", "n/a", "n/a (processor cost)", "startup")]


def main_rows(F, D, V):
    """The default part's campaign, then its calibration's verification."""
    return drive_rows(F) + rate_rows(F) + thermal_rows(F, D) + verification_rows("default", V["default"]) \
        + bench_row(F)


def offnominal_rows(F, V, part="f1300_q200"):
    """The off-nominal part: start-up, rate table, noise, its verification."""
    def v(scen, key, nd=4):
        return fmt(F[f"{part}_{scen}"].get(key), nd)
    return [
        Row("drive lock (amplitude within 1 %, held)",
            f"{v('startup', 'lock_time_s', 3)} s, overshoot {v('startup', 'overshoot_pct', 2)} %", "",
            part, "n/a", NA_DRIVE, f"{part}_startup"),
        Row("scale factor / nonlinearity (+-160 deg/s)",
            f"{v('rate_table', 'scale_factor', 7)} / {v('rate_table', 'nonlinearity_pct', 3)} % FS", "",
            part, "yes", RATE_TABLE_NOTE, f"{part}_rate_table"),
        Row("all noise: ARW (fit) / lowest Allan deviation",
            f"{v('static_allan', 'arw_deg_rth')} deg/rt(h) / {v('static_allan', 'adev_min_dph')} deg/h", "",
            part, "yes", OUT, f"{part}_static_allan"),
    ] + verification_rows(part, V[part])


def table(rows, part_link=part_cell):
    out = ["| figure | simulated | thesis | part (calibration) | compensated | sample | source |",
           "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        part = part_link(r.part, open_loop=not r.part)
        src = r.source if r.source.startswith("`") else f"`{r.source}`"
        out.append(f"| {r.figure} | {r.value} | {r.thesis} | {part} | {r.compensated} | {r.sample} | {src} |")
    return out


def relative(obj, base):
    """obj with every absolute path string made relative to the folder base."""
    if isinstance(obj, dict):
        return {k: relative(v, base) for k, v in obj.items()}
    if isinstance(obj, list):
        return [relative(v, base) for v in obj]
    if isinstance(obj, str) and os.path.isabs(obj) and " " not in obj:
        return os.path.relpath(obj, base)
    return obj


def relative_json_tree(folder):
    """Rewrite every *.json under folder so that its absolute paths are relative to folder."""
    for d, _, files in os.walk(folder):
        for name in files:
            if not name.endswith(".json"):
                continue
            path = os.path.join(d, name)
            with open(path, encoding="utf-8") as fh:
                doc = json.load(fh)
            new = relative(doc, folder)
            if new != doc:
                with open(path, "w", encoding="utf-8") as fh:
                    json.dump(new, fh, indent=1)
                    fh.write("\n")
