"""gyro-transient (run-sim's start-up plot): the 1 % band entry time against a synthetic
first-order start-up, the phase source named, a log that does not start from power-on
refused with exit 2."""
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from gyrotools import csvlog, transient

TOOLS = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def _log(tmp_path, tau=0.005, start=0.0, phase=True, name="startup.csv"):
    t = np.arange(1, 3001) * 1e-3
    amp = 10e-6 * (1 - np.exp(-(t - start).clip(0) / tau)) + start * 1e-6
    p = tmp_path / name
    cols = "t_s,drive_amp_true_m" + (",drive_phase_deg" if phase else "")
    rows = [f"{a:.6f},{b:.7g}" + (f",{5 * math.exp(-x / 0.01):.5g}" if phase else "")
            for a, b, x in zip(t, amp, t)]
    p.write_text(cols + "\n" + "\n".join(rows) + "\n")
    return p


def test_band_entry_of_a_first_order_start(tmp_path):
    res = transient.analyse(csvlog.read_log(str(_log(tmp_path)), need=["drive_amp_true_m"],
                                            want=["drive_phase_deg"]), 0.2)
    # 1 - exp(-t/tau) within 1 %: t = tau ln 100 = 23.0 ms, on the 1 ms grid
    assert res.settle_s == pytest.approx(0.005 * math.log(100), abs=1.1e-3)
    assert res.t_s[-1] <= 0.2 and "firmware" in res.phase_label


def test_command_and_refusal(tmp_path):
    png = tmp_path / "o" / "t.png"
    r = subprocess.run([sys.executable, os.path.join(TOOLS, "gyro-transient"), str(_log(tmp_path)),
                        "--out", str(png)], capture_output=True, text=True)
    assert r.returncode == 0 and png.stat().st_size > 1000, r.stderr
    late = _log(tmp_path, start=0.0, name="late.csv")
    text = late.read_text().splitlines()
    late.write_text("\n".join([text[0]] + text[500:]) + "\n")  # starts at 0.5 s, already up
    r = subprocess.run([sys.executable, os.path.join(TOOLS, "gyro-transient"), str(late),
                        "--out", str(png)], capture_output=True, text=True)
    assert r.returncode == 2 and "power-on" in r.stderr and "Traceback" not in r.stderr
