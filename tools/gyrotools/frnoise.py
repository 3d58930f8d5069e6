"""Rate noise of the force-rebalance loop (sense.mode 1) against the Brownian floor and
its low-frequency noise under the two feedback schemes (tools/fr-noise).

A case is the part of tests/closed_loop/test_cl_sense_fr.c (frpart.py: sense mode at
1600 Hz, the feedback pair at Ks 0.1 (m/s^2)/V^2, the model from the plant's values) on
the ideal preset with the brownian_only scenario's noise settings (every source off but
the Brownian force), then: the feedback scheme (half-frequency or DC+AC), the
feedthrough of the feedback channel into the sense pickoff (plant.pick_sense_ft_spare at
the preset's 1e-3 V/V, or 0), and for the "electrode" study the feedback electrodes'
voltage noise at the plant's defaults (fb_noise_white_v_rthz, fb_noise_1hz_v_rthz: white
and 1/f on each electrode). The record: zero rate (or a constant one), then +100 / -100 / 0 deg/s for 10 s
each, which give the scale factor that refers the output to the input (as the
brownian_only scenario does).

The matched part (--matched): the same part with tuning electrodes tuned onto the drive
(sense.tune 1, frpart.matched_values: the tuning calibration a sweep stages, the model at
the resonance the tuning's code gives), then the calibration flow's rate-table stage run
on each case as tests/closed_loop/test_cl_sense_tune.c runs it, twice (rate_table: at a
matched resonance the mode's phase at the drive frequency moves steeply with a small
error of the model, and the readout's frame with it).

Quadrature nulling (--quad-null): the part with nulling electrodes of QN_DPS_PER_V2
(tests/closed_loop/test_cl_quadnull.c's and check_quadnull_temp.py's; their voltage noise
off with every other source, BROWNIAN_ONLY) and the firmware's quad.null 1 for the record,
so that every loop is closed and the feedback force rebalances what the nulling leaves
rather than the part's 1500 deg/s. The rate table of --matched runs before, on the part
with its electrodes at 0 V, as test_cl_sense_tune.c's calibration does. The record is
judged on the plant's truth (nulled): from the analysis's start on, the quadrature left
(quad_true_dps) within QN_TOL_DPS and the rate valid throughout (quadnull_check).

Sampling: the loop's output band is 500 Hz (sense.fr_lpf_hz, a 2nd-order Butterworth);
a point sample of it every 5 ms (brownian_only's 200 Hz CSV) folds the band between 100
and 500 Hz onto the low frequencies and more than doubles the Allan deviation at short
tau. So the CSV is taken at CSV_RATE_HZ (the output's density at the first alias, 2 kHz,
is below 1 % of its low-frequency level) and averaged here into AVG_RATE_HZ blocks,
streamed through a FIFO (a 10000 s record would be 5 GB of CSV).
"""

from __future__ import annotations

import json
import math
import os
import shlex
import subprocess
import tempfile
import threading

import numpy as np

from . import demodcal, frpart
from .errors import InputError

CSV_RATE_HZ = 2000.0
AVG_RATE_HZ = 100.0
STEP_S = 10.0  # each of the scale factor's steps
EDGE_S = 0.1
# the rate table's run: at rest (the loop settles), then +100 and -100 deg/s; each mean
# after RT_SETTLE_S of its step
RT_STEPS = [[1.0, 0.0], [0.6, 100.0], [0.6, -100.0]]
RT_SETTLE_S = 0.3
RT_CSV_HZ = 1000.0
KB_J_PER_K = 1.380649e-23
# the nulling electrodes of test_cl_quadnull.c: 1500 deg/s at 8.7 V on one set
QN_DPS_PER_V2 = 20.0
QN_TOL_DPS = 1.0  # the nulled quadrature (plant truth), as test_cl_quadnull.c judges it
# nulling on, and the model-made calibration declared nulling's (else it is stale)
QUAD_NULL_FW = ["--set", "firmware.quad.null=1", "--set", "firmware.cal.ref_quad_null=1"]
# the CSV's columns the record keeps (block means; rate_valid's is the valid fraction)
COLUMNS = ["t_s", "rate_dps", "rate_true_dps", "quad_dps", "quad_true_dps", "rate_valid"]

# brownian_only.json's plant settings: the ideal preset, every electronic noise off
BROWNIAN_ONLY = {"preset": "ideal",
                 "drive_noise_white_v_rthz": 0, "drive_noise_1hz_v_rthz": 0,
                 "fb_noise_white_v_rthz": 0, "fb_noise_1hz_v_rthz": 0,
                 "quadnull_noise_white_v_rthz": 0, "quadnull_noise_1hz_v_rthz": 0,
                 "tune_noise_white_v_rthz": 0, "tune_noise_1hz_v_rthz": 0,
                 "pick_drive_noise_v_rthz": 0, "pick_sense_noise_v_rthz": 0,
                 "pick_drive_jitter_s": 0, "pick_sense_jitter_s": 0, "brownian": 1}
FT_SPARE = 1e-3  # the presets' feedthrough of the feedback channel into the sense pickoff


def case_plant(study, ft_on, defaults, quad_null=False):
    """The plant settings of a case beyond frpart's: brownian_only's noise settings, the
    feedthrough, and in the electrode study the feedback electrodes' default noise
    (defaults: the default part's plant values by name); quad_null: the nulling
    electrodes of QN_DPS_PER_V2 (their noise stays off)."""
    p = dict(BROWNIAN_ONLY)
    p["pick_sense_ft_spare"] = FT_SPARE if ft_on else 0.0
    if quad_null:
        p["quadnull_dps_per_v2"] = QN_DPS_PER_V2
    if study == "electrode":
        for k in ("fb_noise_white_v_rthz", "fb_noise_1hz_v_rthz", "fb_noise_fmin_hz"):
            p[k] = defaults[k]
    return p


def scenario(duration_s, seed, cal_path, rate_dps=0.0):
    """The run: duration_s at rate_dps (0: at rest), then the scale factor's steps."""
    steps = [[duration_s, rate_dps], [STEP_S, 100], [STEP_S, -100], [STEP_S, 0]]
    return {"name": "fr_noise", "duration_s": duration_s + 3 * STEP_S, "seed": seed,
            "mode": "closed_loop", "firmware_params": os.path.abspath(cal_path),
            "csv_rate_hz": CSV_RATE_HZ,
            "rate_dps": {"kind": "steps", "edge_s": EDGE_S, "steps": steps}}


def _cat(parts):
    return np.concatenate(parts) if parts else np.empty(0)


class _Averager:
    """Reads the CSV from a FIFO as gyro-sim writes it: the means of COLUMNS over blocks
    of n rows."""

    def __init__(self, path, n):
        self.path, self.n = path, n
        self.parts = []
        self.error = None

    def run(self):
        try:
            import pandas as pd
            k_cols = len(COLUMNS)
            rest = np.empty((0, k_cols))
            for chunk in pd.read_csv(self.path, usecols=COLUMNS, chunksize=200000):
                a = np.vstack([rest, chunk[COLUMNS].to_numpy(dtype=float)])
                k = len(a) // self.n * self.n
                self.parts.append(a[:k].reshape(-1, self.n, k_cols).mean(axis=1))
                rest = a[k:]
        except Exception as e:  # reported by the caller: a thread cannot raise
            self.error = e

    def arrays(self):
        """The block means by column name."""
        a = np.vstack(self.parts) if self.parts else np.empty((0, len(COLUMNS)))
        return {c: a[:, i] for i, c in enumerate(COLUMNS)}


def run_case(exe, args, scen, log=print):
    """Runs gyro-sim on scen with args (the --set list), its CSV averaged through a FIFO.
    Returns (the block means of COLUMNS by name, the run's JSON, the command line)."""
    with tempfile.TemporaryDirectory() as tmp:
        sc_path = os.path.join(tmp, "fr_noise.json")
        with open(sc_path, "w", encoding="utf-8") as f:
            json.dump(scen, f)
        fifo, js = os.path.join(tmp, "rate.csv"), os.path.join(tmp, "run.json")
        os.mkfifo(fifo)
        avg = _Averager(fifo, int(round(CSV_RATE_HZ / AVG_RATE_HZ)))
        th = threading.Thread(target=avg.run)
        th.start()
        cmd = [exe, "--scenario", sc_path, "--csv", fifo, "--no-analysis", "--quiet",
               "--json", js] + list(args)
        log("# " + shlex.join(cmd))
        r = subprocess.run(cmd, capture_output=True, text=True)
        th.join()
        if r.returncode != 0:
            raise RuntimeError(f"gyro-sim failed ({r.returncode}): {r.stderr.strip()}")
        if avg.error is not None:
            raise RuntimeError(f"reading the CSV: {avg.error}")
        with open(js, encoding="utf-8") as f:
            run = json.load(f)
    return avg.arrays(), run, cmd


def scale_factor(t, rate, true, t0):
    """Output per input rate from the +-100 deg/s steps after t0 (their first and last
    second left out), and the mean output at zero rate before t0."""
    def mean_in(a, b):
        sel = (t > t0 + a + 1.0) & (t < t0 + b - 1.0)
        return rate[sel].mean(), true[sel].mean()
    up, dn = mean_in(0.0, STEP_S), mean_in(STEP_S, 2 * STEP_S)
    return (up[0] - dn[0]) / (up[1] - dn[1])


def brownian_floor_dph(p, fig):
    """The thermomechanical floor (4-24) of the sense axis as two-sided N, deg/h/rtHz, at
    the run's mean drive frequency, amplitude and structure temperature (gyro-sim's
    brownian_noise analysis, host_sim/gyro_sim/main.c brownian_floor_dph)."""
    w1 = 2.0 * math.pi * fig["mean_drive_freq_hz"]
    tk = fig["mean_struct_temp_k"]
    w2 = 2.0 * math.pi * p["f_sense_hz"] * (1.0 - 0.5 * p["ket_per_k"] * (tk - p["temp_ref_k"]))
    om = math.sqrt(4.0 * KB_J_PER_K * tk * w2 / (p["mass_kg"] * p["q_sense"])) / (
        2.0 * fig["mean_drive_amp_m"] * w1)
    return math.degrees(om) * 3600.0


def adev(rate_dps, fs_hz, taus):
    """Overlapping Allan deviation (allantools) in deg/h at taus (s)."""
    import allantools
    t, ad, _, _ = allantools.oadev(rate_dps, rate=fs_hz, data_type="freq", taus=taus)
    return t, ad * 3600.0


def arw_coeff(tau, ad_dph, lo=0.1, hi=10.0):
    """N (deg/h/rtHz, two-sided) of the white region: the geometric mean of
    adev(tau) sqrt(tau) over lo <= tau <= hi."""
    sel = (tau >= lo) & (tau <= hi)
    return float(np.exp(np.mean(np.log(ad_dph[sel] * np.sqrt(tau[sel])))))


def at_tau(tau, ad_dph, t0):
    """The Allan deviation at the tau nearest t0 (log scale), None when out of range."""
    if len(tau) == 0 or t0 > tau[-1] * 1.01 or t0 < tau[0] / 1.01:
        return None
    return float(ad_dph[np.argmin(np.abs(np.log(tau / t0)))])


def quadnull_check(rec, duration_s, settle_s):
    """Whether the nulling had settled when the analysis starts (settle_s) and held to the
    record's end (duration_s), on the block means rec: the quadrature left (plant truth)
    within QN_TOL_DPS and the rate valid on every block; the time from which both held,
    and the quadrature left and read (the firmware's quad_dps) over the record."""
    t = rec["t_s"]
    rec_sel = t < duration_s
    ok = (np.abs(rec["quad_true_dps"]) <= QN_TOL_DPS) & (rec["rate_valid"] >= 1.0)
    bad = np.nonzero(~ok & rec_sel)[0]
    t_held = float(t[bad[-1] + 1]) if len(bad) else float(t[0])
    sel = rec_sel & (t >= settle_s)
    qt, qf = rec["quad_true_dps"][sel], rec["quad_dps"][sel]
    return {"nulled": bool(t_held <= settle_s) and bool(sel.any()),
            "nulled_and_valid_from_s": t_held, "tol_dps": QN_TOL_DPS,
            "quad_true_mean_dps": float(qt.mean()), "quad_true_max_abs_dps":
            float(np.abs(qt).max()), "quad_true_std_dps": float(qt.std()),
            "quad_fw_mean_dps": float(qf.mean()), "quad_fw_std_dps": float(qf.std()),
            "rate_valid_fraction": float(rec["rate_valid"][sel].mean())}


def analyse(rec, run, duration_s, settle_s):
    """The case's figures from its averaged record (COLUMNS by name): scale factor, N
    against the floor, the Allan deviation at 10, 100 and 1000 s, and the curve."""
    t, rate, true = rec["t_s"], rec["rate_dps"], rec["rate_true_dps"]
    sf = scale_factor(t, rate, true, duration_s)
    sel = (t >= settle_s) & (t < duration_s)
    x = rate[sel] / sf
    taus = np.logspace(-2, math.log10(len(x) / AVG_RATE_HZ / 4.0), 41)
    tau, ad = adev(x, AVG_RATE_HZ, taus)
    floor = brownian_floor_dph(run["params"], run["figures"])
    n = arw_coeff(tau, ad)
    return {"scale_factor": sf, "arw_coeff_dph_rthz": n, "brownian_floor_dph_rthz": floor,
            "arw_over_floor": n / floor, "mean_rate_dph": float(x.mean() * 3600.0),
            "adev_10s_dph": at_tau(tau, ad, 10.0), "adev_100s_dph": at_tau(tau, ad, 100.0),
            "adev_1000s_dph": at_tau(tau, ad, 1000.0),
            "rate_valid_fraction": run["figures"]["rate_valid_fraction"],
            "realtime_factor_cpu": run.get("realtime_factor_cpu"),
            "tau_s": tau.tolist(), "adev_dph": ad.tolist()}


def case_args(exe, cal_path, scheme, study, ft_on, q_sense, extra, matched=False,
              quad_null=False, own_cal=False):
    """gyro-sim --set arguments of a case (frpart.fr_args on the ideal preset, matched or
    not, then the case's plant settings, then extra). quad_null: the part with nulling
    electrodes (case_plant); the firmware's quad.null 1 is QUAD_NULL_FW, for the caller
    to add after the calibration. own_cal: cal_path is the part's own calibration
    (tools/calibrate on calibration_part's settings): the plant's arguments alone."""
    defaults = frpart.plant_values(exe)
    plant = case_plant(study, ft_on, defaults, quad_null)
    plant.pop("preset")
    args = frpart.fr_args(exe, cal_path, scheme, q_sense=q_sense, plant=plant,
                          base=["plant.preset=ideal"], matched=matched, model=not own_cal)
    for s in extra:
        args += ["--set", s]
    return args


# what a case's noise settings change and a calibration does not depend on: the part a
# calibration for --cal is made on is the case's without them (calibration_part)
NOISE_KEYS = tuple(k for k in BROWNIAN_ONLY if k not in ("preset", "brownian"))


def calibration_part(q_sense=1e4, quad_null=False, scheme="half"):
    """The plant settings (--set strings) of the part a case runs, for tools/calibrate:
    the ideal preset's part with the case's sense mode, feedback pair and nulling
    electrodes, its noise as the preset has it (the case's noise settings do not change
    what a calibration measures)."""
    fr = {"f_sense_hz": 1600.0, "q_sense": q_sense, "fb_mode": frpart.FB_MODE[scheme],
          "ks_fb_mps2_per_v2": frpart.KS_FB}
    if quad_null:
        fr["quadnull_dps_per_v2"] = QN_DPS_PER_V2
    return ["plant.preset=ideal"] + [f"plant.{k}={v:.9g}" for k, v in fr.items()]


def check_own_cal(values, scheme, quad_null):
    """A --cal set must be the case's configuration: force rebalance with its scheme and
    nulling as asked. Raises InputError (why) otherwise."""
    want = {"sense.mode": 1, "sense.fb_scheme": frpart.FB_SCHEME[scheme],
            "quad.null": int(quad_null)}
    bad = [f"{k} {values.get(k)} (the case needs {v})" for k, v in want.items()
           if int(values.get(k, -1)) != v]
    if bad:
        raise InputError("--cal: not a calibration of this case's configuration: "
                         + ", ".join(bad))


def wrap_deg(x):
    return (x + 180.0) % 360.0 - 180.0


def rate_table(exe, args, cal_path, seed, passes=2, log=print):
    """The calibration flow's rate-table stage (calflow.py rate_table, demodcal.py) on a
    case, as tests/closed_loop/test_cl_sense_tune.c's flow_rate_table: from power-on at
    rest, +100 and -100 deg/s (RT_STEPS); the response's angle alpha turns
    rate.demod_phase_deg and sense.fb_phase_deg (the readout's frame), its length the
    scale. passes times, each on the last one's values. Returns the --set arguments that
    carry the result (to follow args) and each pass's figures."""
    extra, passes_out = [], []
    duration = sum(d for d, _ in RT_STEPS)
    for _ in range(passes):
        with tempfile.TemporaryDirectory() as tmp:
            scen = {"name": "fr_rate_table", "duration_s": duration, "seed": seed,
                    "mode": "closed_loop", "firmware_params": os.path.abspath(cal_path),
                    "csv_rate_hz": RT_CSV_HZ,
                    "rate_dps": {"kind": "steps", "edge_s": 0.0, "steps": RT_STEPS}}
            sc_path, csv = os.path.join(tmp, "rt.json"), os.path.join(tmp, "rt.csv")
            saved = os.path.join(tmp, "values.json")
            with open(sc_path, "w", encoding="utf-8") as f:
                json.dump(scen, f)
            cmd = [exe, "--scenario", sc_path, "--csv", csv, "--no-analysis", "--quiet",
                   "--save-params", saved] + list(args) + extra
            log("# " + shlex.join(cmd))
            r = subprocess.run(cmd, capture_output=True, text=True)
            if r.returncode != 0:
                raise RuntimeError(f"gyro-sim failed ({r.returncode}): {r.stderr.strip()}")
            import pandas as pd
            log_ = pd.read_csv(csv, usecols=["t_s", "rate_true_dps", "rate_dps", "quad_dps"])
            with open(saved, encoding="utf-8") as f:
                values = {e["name"]: e["value"] for e in json.load(f)["params"]}
        res = demodcal.analyse(log_["t_s"], log_["rate_dps"], log_["quad_dps"],
                               values["rate.demod_phase_deg"], values["rate.scale_dps"],
                               rate_true_dps=log_["rate_true_dps"], settle_s=RT_SETTLE_S,
                               min_avg_s=0.2)
        fb = wrap_deg(values["sense.fb_phase_deg"] + res.alpha_deg)
        extra = ["--set", f"firmware.rate.demod_phase_deg={res.phase_deg:.9g}",
                 "--set", f"firmware.rate.scale_dps={res.scale_dps:.9g}",
                 "--set", f"firmware.sense.fb_phase_deg={fb:.9g}"]
        passes_out.append({"alpha_deg": res.alpha_deg, "gain": res.gain,
                           "rate.demod_phase_deg": res.phase_deg,
                           "rate.scale_dps": res.scale_dps, "sense.fb_phase_deg": fb})
        log(f"# rate table: alpha {res.alpha_deg:+.3f} deg, gain {res.gain:.4f}")
    return extra, passes_out


def plot(cases, out_dir, title):
    """Allan deviation (deg/h) against tau (s), log-log, each case, with the Brownian
    floor's white line of the first."""
    from . import plotting
    fig, ax = plotting.figure(width_in=8.0, height_in=5.5)
    for i, c in enumerate(cases):
        r = c["result"]
        ax.loglog(r["tau_s"], r["adev_dph"], "o-", ms=3, color=f"C{i}",
                  label=f"{c['label']}: N {r['arw_coeff_dph_rthz']:.3g} deg/h/rtHz")
    if cases:
        r = cases[0]["result"]
        tau = np.array(r["tau_s"])
        ax.loglog(tau, r["brownian_floor_dph_rthz"] / np.sqrt(tau), "k--",
                  label=f"Brownian floor (4-24), N {r['brownian_floor_dph_rthz']:.3g} deg/h/rtHz")
    plotting.finish(ax, title=title, xlabel="averaging time tau (s)",
                    ylabel="Allan deviation of the rate (deg/h)")
    return plotting.save(fig, out_dir, "fr_noise_allan.png")
