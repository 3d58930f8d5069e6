"""calport end to end on a simulated part behind gyro-sim's UART session (--uart-pty,
--pace 0): a run played by the simulated bench (a table step, a command), logged in the
part's own time with the bench's setpoints as truth; the self-calibration over the port.
Needs $GYRO_SIM (ctest python_calport sets it); about 10 s."""
import os
import subprocess

import numpy as np
import pytest

from gyrotools import calport, csvlog, paramset

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))))
CAL = os.path.join(ROOT, "host_sim", "parts", "default", "calibration.json")


@pytest.fixture
def port(tmp_path):
    sim = os.environ.get("GYRO_SIM")
    if not sim or not os.access(sim, os.X_OK):
        pytest.skip("$GYRO_SIM not set to a built gyro-sim (run under ctest)")
    link = str(tmp_path / "gyro.pty")
    proc = subprocess.Popen([sim, "--scenario", os.path.join(ROOT, "host_sim", "scenarios",
                                                             "startup.json"),
                             "--duration", "100000", "--quiet", "--pace", "0",
                             f"--uart-pty={link}"], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().startswith("pty ")
    yield link
    proc.terminate()
    proc.wait(timeout=10)


def test_a_run_is_played_and_logged_in_the_parts_time(port, tmp_path):
    scen = {"duration_s": 4.0, "csv_rate_hz": 200,
            "rate_dps": {"kind": "steps", "edge_s": 0.1, "steps": [[1.5, 0], [1.5, 50], [1, 0]]},
            "commands": [[3.5, "status"]]}
    out = tmp_path / "run.csv"
    replies = calport.PortTarget(port, "emu").run(CAL, scen, str(out))
    log = csvlog.read_log(str(out), need=["rate_dps", "rate_true_dps", "rate_valid",
                                          "rate_invalid", "mode"])
    t = log["t_s"]
    # t = 0 at the drive's first record out of OFF, one record (5 ms) at most off.
    assert 0.0 <= t[0] <= 0.005 and t[-1] == pytest.approx(4.0, abs=0.01)
    assert np.all(np.diff(t) == pytest.approx(0.005, abs=1e-9))  # no record lost
    truth = log["rate_true_dps"]
    # The bench's setpoint, timed by the part: the table's move starts when the flow has
    # seen 1.5 s of the part's time and its command has arrived, which an unpaced
    # simulator (about 50x real time) has run past by the link's round trip (about 0.5 s
    # of its time here); the truth is when it really moved, and the output follows it
    # within the output filter's delay.
    up = t[np.argmax(truth > 25.0)]
    assert 1.5 <= up <= 2.5
    # (The valid output: in the acquisition after `drive on` the rate channel starts
    # afresh, as at a power-on, and its transient is flagged invalid.)
    follows = (log["rate_dps"] > 25.0) & (log["rate_valid"] == 1)
    assert t[np.argmax(follows)] - up == pytest.approx(0.005, abs=0.01)
    held = (t > up + 0.5) & (t < up + 1.0) & (log["rate_valid"] > 0.5)
    assert held.sum() >= 95 and np.all(truth[held] == 50.0)  # 0.5 s at 200 Hz
    assert np.mean(log["rate_dps"][held]) == pytest.approx(50.0, rel=0.01)
    assert len(replies) == 1 and "ok" in replies[0] and "LOCKED" in replies[0]


def test_the_self_calibration_over_the_port_saves_a_loadable_set(port, tmp_path):
    out = tmp_path / "selfcal.json"
    figs = calport.PortTarget(port, "emu").selfcal(str(out))
    assert figs["selfcal_f0_hz"] == pytest.approx(1489.9, abs=0.5)
    assert figs["selfcal_q"] == pytest.approx(33.3, rel=0.05)
    v = paramset.read(str(out)).values()
    assert v["drive.freq_hz"] == pytest.approx(figs["selfcal_f0_hz"], abs=0.01)


def test_the_self_calibration_over_the_port_runs_in_the_configuration_asked(port, tmp_path):
    out = tmp_path / "selfcal.json"
    calport.PortTarget(port, "emu").selfcal(str(out), {"quad.null": 1})
    assert paramset.read(str(out)).values()["quad.null"] == 1


def test_a_configuration_the_part_refuses_stops_the_self_calibration(port, tmp_path):
    out = tmp_path / "selfcal.json"
    with pytest.raises(calport.PortError, match="sense.mode 7"):
        calport.PortTarget(port, "emu").selfcal(str(out), {"sense.mode": 7})
    assert not out.exists()
