"""The five command-line tools end to end on small synthetic logs: exit status, printed
figures, the JSON keys and PNGs they write, and one-line errors on bad input."""
import json
import os
import stat
import subprocess
import sys

import numpy as np
import pytest
import synth
from test_freqresp import F, truth
from test_gyroctl_bridge import FAKE
from test_scalefactor import DWELL, RATES, table_log
from test_tempcomp import cooldown

from gyrotools import paramset

TRUTH = ("rate_true_dps", "t_ambient_c", "t_struct_c")
SCRIPTS = ("gyro-allan", "gyro-psd", "gyro-scalefactor", "gyro-freqresp", "gyro-tempcomp")


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("logs")
    g = np.random.default_rng(51)
    n, fs = 2 ** 14, 100.0
    x = synth.white_dps(n, fs, 18.7, g) + synth.flicker_dps(n, fs, 31.3, g)
    static = synth.write_log(d / "static.csv", {"t_s": np.arange(n) / fs, "rate_dps": x},
                             drop=TRUTH)
    t, r, y = table_log()
    table = synth.write_log(d / "table.csv", {"t_s": t, "rate_true_dps": r, "rate_dps": y})
    table_nt = synth.write_log(d / "table_gyroctl.csv", {"t_s": t, "rate_dps": y},
                               drop=TRUTH)
    h = truth(F)
    sweep = d / "sweep.csv"
    np.savetxt(sweep, np.column_stack([F, np.abs(h), np.degrees(np.angle(h))]),
               delimiter=",", header="f_hz, amp, phase_deg", comments="", fmt="%.10g")
    t, p, y, board = cooldown([58.533, 34.59], seed=52)
    cool = synth.write_log(d / "cool.csv", {"t_s": t, "rate_dps": y, "p_deg": p,
                                            "t_board_c": board}, drop=TRUTH)
    return {"static": static, "table": table, "table_nt": table_nt, "sweep": str(sweep),
            "cool": cool, "dir": d}


def load(out, name):
    with open(os.path.join(out, name)) as fh:
        return json.load(fh)


def test_scripts_are_executable_python(tools_dir):
    for s in SCRIPTS:
        path = os.path.join(tools_dir, s)
        assert os.stat(path).st_mode & stat.S_IXUSR, s
        with open(path) as fh:
            assert fh.readline().strip() == "#!/usr/bin/env python3"


def test_gyro_allan(run_script, logs, tmp_path):
    code, out, err = run_script("gyro-allan", [logs["static"], "--out", tmp_path])
    assert code == 0, err
    assert "angle random walk N" in out and "bias instability B" in out
    j = load(tmp_path, "allan.json")
    for k in ("arw_dph_per_rthz", "arw_deg_per_rth", "arw_one_sided_asd_dph_per_rthz",
              "arw_fit_tau_range_s", "adev_at_1s_dph", "bias_instability_dph",
              "bias_instability_is_upper_bound", "tau_at_min_s", "rate_ramp_dph_per_h",
              "rate_ramp_dps_per_h", "tau_s", "adev_dph", "adev_ci68_lo_dph",
              "adev_ci68_hi_dph", "fs_hz", "convention", "plots"):
        assert k in j, k
    assert j["fs_hz"] == pytest.approx(100.0)
    assert j["arw_dph_per_rthz"] == pytest.approx(18.7, rel=0.05)
    assert os.path.isfile(tmp_path / "allan.png")


def test_gyro_psd(run_script, logs, tmp_path):
    code, out, err = run_script("gyro-psd", [logs["static"], "--out", tmp_path,
                                             "--band", "1", "40"])
    assert code == 0, err
    j = load(tmp_path, "psd.json")
    for k in ("white_asd_one_sided_dps_per_rthz", "white_asd_one_sided_dph_per_rthz",
              "arw_N_two_sided_dph_per_rthz", "arw_N_deg_per_rth", "band_hz",
              "n_segments", "resolution_hz"):
        assert k in j, k
    assert j["arw_N_two_sided_dph_per_rthz"] == pytest.approx(18.7, rel=0.06)
    assert "deg/h/rtHz" in out and os.path.isfile(tmp_path / "psd.png")


def test_gyro_scalefactor_with_and_without_truth(run_script, logs, tmp_path):
    code, out, err = run_script("gyro-scalefactor", [logs["table"], "--out", tmp_path,
                                                     "--settle", "1.5"])
    assert code == 0, err
    j = load(tmp_path, "scalefactor.json")
    for k in ("scale_factor_out_per_dps", "bias_out", "nonlinearity_rms_percent_of_fs",
              "full_scale_dps", "rms_residual_dps", "scale_factor_pos_out_per_dps",
              "scale_factor_neg_out_per_dps", "asymmetry_fraction", "segments",
              "half_differences"):
        assert k in j, k
    assert j["segments_from"] == "rate_true_dps" and len(j["segments"]) == len(RATES)
    code, out, err = run_script("gyro-scalefactor", [logs["table_nt"], "--out", tmp_path])
    assert code == 2 and "missing column 'rate_true_dps'" in err and "--table" in err
    assert len(err.strip().splitlines()) == 1
    sched = ",".join(f"{x:g}:{DWELL:g}" for x in RATES)
    code, out, err = run_script("gyro-scalefactor", [logs["table_nt"], "--out", tmp_path,
                                                     "--table", sched, "--settle", "1.5"])
    assert code == 0, err
    k = load(tmp_path, "scalefactor.json")
    assert k["segments_from"] == "--table"
    assert k["scale_factor_out_per_dps"] == pytest.approx(j["scale_factor_out_per_dps"])
    # How each was made: the command line as given and every option, defaults included.
    assert "--settle 1.5" in j["command"] and j["options"]["settle"] == 1.5
    assert j["options"]["min_avg"] == pytest.approx(0.5) and "argv_" not in j["options"]
    assert k["table_aligned"]["correlation"] > 0.9 and k["options"]["table"] == sched


def test_gyro_freqresp(run_script, logs, tmp_path):
    code, out, err = run_script("gyro-freqresp", [logs["sweep"], "--out", tmp_path,
                                                  "--lag", "const"])
    assert code == 0, err
    j = load(tmp_path, "freqresp.json")
    for k in ("f0_hz", "q", "peak_gain", "peak_gain_db", "f_peak_hz", "f_3db_lo_hz",
              "f_3db_hi_hz", "q_from_3db", "phase_at_f0_deg", "lag_phi0_deg",
              "lag_delay_s", "dc_gain", "f0_std_hz", "q_std"):
        assert k in j, k
    assert j["f0_hz"] == pytest.approx(1489.9, rel=1e-6)
    assert j["phase_at_f0_deg"] == pytest.approx(-99.56, abs=1e-3)
    assert "-3 dB points" in out


def test_gyro_tempcomp_and_write(run_script, logs, tmp_path, monkeypatch):
    bindir = tmp_path / "bin"
    bindir.mkdir()
    (bindir / "gyroctl").write_text(FAKE)
    (bindir / "gyroctl").chmod(0o755)
    calls = tmp_path / "calls.jsonl"
    monkeypatch.setenv("PATH", f"{bindir}{os.pathsep}{os.environ['PATH']}")
    monkeypatch.delenv("GYROCTL", raising=False)
    monkeypatch.setenv("FAKE_GYROCTL_LOG", str(calls))
    out_dir = tmp_path / "out"
    code, out, err = run_script("gyro-tempcomp", [logs["cool"], "--out", out_dir,
                                                  "--write", "/dev/ttyACM0"])
    assert code == 0, err
    j = load(out_dir, "tempcomp.json")
    assert j["p_fit"]["order"] == 1
    assert j["p_fit"]["coeffs"] == pytest.approx([58.533, 34.59, 0, 0], abs=0.03)
    assert j["t_fit"]["variable"] == "t_board_c"
    assert j["t_fit"]["residual_std_dps"] > 5 * j["p_fit"]["residual_std_dps"]
    for k in ("cv_rmse_dps_by_order", "residual_std_dps", "residual_p2p_dps"):
        assert k in j["p_fit"]
    # In the deviation from the middle of the log's P span, with the range it covers
    # and no gradient term (tempcomp.firmware_bias).
    assert set(j["firmware_bias_params"]) == {"rate.bias_c0_dps", "rate.bias_c1_dps_per_deg",
                                              "rate.bias_c2_dps_per_deg2",
                                              "rate.bias_c3_dps_per_deg3", "cal.ref_p_deg",
                                              "rate.p_range_deg", "rate.bias_grad_dps_per_deg"}
    (sent,) = [json.loads(x) for x in calls.read_text().splitlines()]
    assert sent[:3] == ["--port", "/dev/ttyACM0", "load-params"] and sent[4:] == ["--merge"]
    written = paramset.read(str(calls) + ".set").values()
    assert list(written) == list(j["firmware_bias_params"])
    assert j["written_to_gyro"]["port"] == "/dev/ttyACM0"
    for png in ("tempcomp_bias_vs_p.png", "tempcomp_bias_vs_t.png", "tempcomp_residual.png"):
        assert os.path.isfile(out_dir / png)


@pytest.mark.parametrize("script, args, msg", [
    ("gyro-allan", ["{empty}"], "empty file"),
    ("gyro-allan", ["{static}", "--column", "quad"], "deg/s"),
    ("gyro-psd", ["{missing}"], "cannot open"),
    ("gyro-freqresp", ["{static}"], "missing column 'f_hz'"),
    ("gyro-tempcomp", ["{static}"], "p_deg does not change"),
    ("gyro-scalefactor", ["{table}", "--table", "1:x"], "two numbers"),
    ("gyro-allan", ["{static}", "--bogus"], "unrecognized arguments"),
])
def test_bad_input_is_one_line(run_script, logs, tmp_path, script, args, msg):
    empty = logs["dir"] / "empty.csv"
    empty.write_text("")
    subst = {"empty": str(empty), "missing": str(logs["dir"] / "nope.csv"),
             "static": logs["static"], "table": logs["table"]}
    code, out, err = run_script(script, [a.format(**subst) for a in args]
                                + ["--out", tmp_path])
    assert code == 2
    assert msg in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1 and err.startswith(script + ": error: ")


def test_real_process_exit_status(tools_dir, logs, tmp_path):
    p = subprocess.run([sys.executable, os.path.join(tools_dir, "gyro-psd"),
                        str(logs["dir"] / "nope.csv"), "--out", str(tmp_path)],
                       capture_output=True, text=True, check=False)
    assert p.returncode == 2 and p.stdout == ""
    assert p.stderr.strip().startswith("gyro-psd: error: ") and "Traceback" not in p.stderr
