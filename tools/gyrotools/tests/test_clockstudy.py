"""tools/clock-study: its options are refused with a reason (exit 2, nothing run), and its
read-offs are right on constructed logs: the resolution of a white frequency noise is
sigma / sqrt(tau rate) in K through kET/2, and the table gives each clock's moves against
the first."""

import math
import os

import numpy as np
import pytest

from gyrotools import clockstudy

CAL = os.path.join(os.path.dirname(__file__), "..", "..", "..", "host_sim", "parts",
                   "default", "calibration.json")


@pytest.mark.parametrize("args, why", [
    (["--cal", CAL, "--clock", "1,x"], "comma-separated"),
    (["--cal", CAL, "--clock", "5000"], "+-1000"),
    (["--cal", CAL, "--settle", "115"], "--settle"),
    (["--cal", CAL, "--ambient", "120"], "--ambient"),
    (["--cal", CAL, "--set", "firmware.rate.scale_dps=1"], "only plant"),
    (["--cal", CAL, "--gyro-sim", "/nonexistent/gyro-sim"], "no simulator"),
])
def test_bad_options_refused(run_script, tmp_path, args, why):
    code, out, err = run_script("clock-study", args + ["--out", tmp_path / "o"])
    assert code == 2 and why in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_bad_calibration_refused(run_script, tmp_path):
    bad = tmp_path / "cal.json"
    bad.write_text("{not json")
    sim = tmp_path / "sim"
    sim.write_text("#!/bin/sh\nexit 1\n")
    sim.chmod(0o755)
    code, _, err = run_script("clock-study", ["--cal", bad, "--gyro-sim", sim,
                                              "--out", tmp_path / "o"])
    assert code == 2 and "cal.json" in err and "Traceback" not in err


def test_resolution_of_white_frequency_noise():
    rng = np.random.default_rng(3)
    rate, n, sigma = 100.0, 60000, 2e-8
    t = np.arange(n) / rate
    f = 1490.0 * (1.0 + sigma * rng.standard_normal(n))
    res = clockstudy.resolution({"t_s": t, "f_drive_hz": f}, 0.0, 4e-5)
    tau, adev_k = clockstudy.at_tau(res, 1.0)
    assert tau == pytest.approx(1.0)
    want = sigma / math.sqrt(rate * tau) / 2e-5
    assert adev_k == pytest.approx(want, rel=0.1)
    assert res["ppm_per_k"] == pytest.approx(20.0)


def test_table_moves_against_the_first():
    base = {"clock_ppm": 0.0, "p_f_deg": 10.0, "f_drive_hz": 1490.0, "bias_dps": 0.01,
            "bias_unc_dps": 1.0, "valid": 1.0}
    fast = dict(base, clock_ppm=20.0, p_f_deg=55.0, f_drive_hz=1490.0 * (1 - 20e-6),
                bias_dps=-2.7, valid=0.5)
    never = dict(base, clock_ppm=-20.0, bias_dps=None, valid=0.0)
    lines = clockstudy.table([base, fast, never], base).splitlines()
    assert "| +20 ppm | +45.000 deg | -20.00 ppm | -2.700 deg/s | +1.000 deg/s | 50 % |" in lines
    assert "| -20 ppm | +0.000 deg | +0.00 ppm | n/a | +1.000 deg/s | 0 % |" in lines
