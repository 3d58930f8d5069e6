"""gyroctl end to end against the gyro running on the simulated plant: gyro-sim
--uart-pty runs the real application on the default plant in real time behind a
pseudo-terminal. Through the serial port: the drive locks; a new amplitude setpoint
set with gyroctl moves the real drive loop (the demodulated amplitude follows, the gyro
re-locks without a fault); a bad value changes nothing; a telemetry log shows it."""
import csv
import math
import os
import subprocess
import sys
import threading
import time

import pytest


def ctl(gyroctl, port, *args):
    return subprocess.run(gyroctl + ["--port", port] + list(args), capture_output=True,
                          text=True, timeout=60)


def status(gyroctl, port):
    r = ctl(gyroctl, port, "status")
    assert r.returncode == 0, r.stderr
    out = {}
    for line in r.stdout.splitlines():
        k, _, v = line.partition(" ")
        out[k] = v
    return out


def wait_locked(gyroctl, port, timeout_s=10.0):
    t0 = time.time()
    while time.time() - t0 < timeout_s:
        s = status(gyroctl, port)
        if s.get("mode") == "LOCKED":
            return s
        time.sleep(0.2)
    pytest.fail(f"not LOCKED within {timeout_s} s: {s}")


def test_setpoint_moves_the_loop(sim, gyroctl, tmp_path):
    s = wait_locked(gyroctl, sim)
    assert abs(float(s["drive_amp_v"]) / 0.349 - 1.0) < 0.02
    # A bad value is refused and changes nothing.
    r = ctl(gyroctl, sim, "set", "drive.amp_set_v", "abc")
    assert r.returncode == 1 and "err VALUE" in r.stderr
    assert ctl(gyroctl, sim, "get", "drive.amp_set_v").stdout.strip() == "0.349"
    # A new setpoint: the real loop moves the drive and re-locks, no fault.
    r = ctl(gyroctl, sim, "set", "drive.amp_set_v", "0.25")
    assert r.returncode == 0, r.stderr
    time.sleep(0.5)
    s = wait_locked(gyroctl, sim)
    assert abs(float(s["drive_amp_v"]) / 0.25 - 1.0) < 0.02
    assert s["fault_count"] == "0"
    # The telemetry shows the drive at the new amplitude.
    out = tmp_path / "log.csv"
    r = ctl(gyroctl, sim, "log", "drive_amp_v", "rate_dps", "--rate", "200", "--duration", "1.5",
            "--out", str(out))
    assert r.returncode == 0, r.stderr
    rows = [row for row in csv.reader(ln for ln in open(out) if not ln.startswith("#"))]
    # Fields come in the firmware's table order (rate before drive amplitude), under
    # the names asked for.
    assert rows[0] == ["t_s", "rate_dps", "drive_amp_v"]
    amps = [float(r_[2]) for r_ in rows[1:]]
    assert len(amps) == 300
    assert abs(sum(amps) / len(amps) / 0.25 - 1.0) < 0.01
    # The analysis tools take the telemetry name and gyro-sim's name for it alike.
    psd = [sys.executable, os.path.join(os.path.dirname(gyroctl[1]), "gyro-psd")]
    for name in ("drive_amp_v", "drive_amp"):
        r = subprocess.run(psd + [str(out), "--column", name, "--band", "1", "50",
                                  "--out", str(tmp_path / name)], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr


def test_fields_lists_the_telemetry(sim, gyroctl):
    r = ctl(gyroctl, sim, "fields")
    assert r.returncode == 0, r.stderr
    rows = {ln.split()[0]: ln.split()[1:] for ln in r.stdout.splitlines()}
    assert rows["rate_dps"] == ["f32", "deg/s"] and rows["flags"] == ["u32", "-"]
    assert "drive_amp_v" in rows


def test_log_reports_the_gyro_going_away(gyro_sim, tmp_path, gyroctl):
    """A simulator that ends during a log: a sentence and exit 3, no traceback."""
    scen = os.path.join(os.environ.get("GYRO_SCENARIOS", ""), "startup.json")
    link = str(tmp_path / "gyro.pty")
    proc = subprocess.Popen([gyro_sim, "--scenario", scen, "--duration", "60", "--quiet",
                             f"--uart-pty={link}"], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().startswith("pty ")
    threading.Timer(1.5, proc.terminate).start()
    r = ctl(gyroctl, link, "log", "rate_dps", "--rate", "100", "--duration", "30",
            "--out", str(tmp_path / "gone.csv"))
    proc.wait(timeout=10)
    assert r.returncode == 3, (r.returncode, r.stderr)
    assert "went away" in r.stderr and "Traceback" not in r.stderr


def test_gain_changes_the_loop(sim, gyroctl):
    """Set the loop gains over the serial port and see the loop answer differently: at
    the designed 30 Hz a setpoint step is done by the time the next command gets an
    answer (a gyroctl call takes a few hundred ms); with manual amplitude-PI gains for a
    0.05 Hz loop (time constant 3.2 s) it is still far from done."""
    wait_locked(gyroctl, sim)
    assert ctl(gyroctl, sim, "set", "drive.amp_set_v", "0.30").returncode == 0
    fast = float(status(gyroctl, sim)["drive_amp_v"])
    assert abs(fast / 0.30 - 1.0) < 0.03
    time.sleep(0.3)
    # Manual PI gains for a 0.05 Hz loop: kp = wc tau / K, ki = kp / tau with the
    # default model (tau = 2Q/wn = 7.12 ms, K = 0.00546 V/V^2), wc = 2 pi 0.05.
    r = ctl(gyroctl, sim, "set", "drive.amp_kp", "0.41", "drive.amp_ki", "57.6")
    assert r.returncode == 0, r.stderr
    assert ctl(gyroctl, sim, "get", "drive.amp_kp").stdout.strip() == "0.41"
    t0 = time.time()
    assert ctl(gyroctl, sim, "set", "drive.amp_set_v", "0.349").returncode == 0
    slow = float(status(gyroctl, sim)["drive_amp_v"])
    elapsed = time.time() - t0
    # After `elapsed` seconds a 0.05 Hz first-order loop has covered 1 - exp(-elapsed/3.2)
    # of the step; allow for the time the two calls took to start.
    done = (slow - 0.30) / (0.349 - 0.30)
    assert done < 1.0 - math.exp(-(elapsed + 0.2) / 3.2) + 0.1
    assert done < 0.8
    assert status(gyroctl, sim)["fault_count"] == "0"


def emu(gyroctl, port, line):
    """One `emu` line through the shell: (its `- key value` data as a dict, its final
    line). The shell exits 1 after an err reply."""
    r = subprocess.run(gyroctl + ["--port", port, "shell"], input=line + "\n",
                       capture_output=True, text=True, timeout=60)
    assert r.returncode in (0, 1) and "Traceback" not in r.stderr, r.stderr
    lines = r.stdout.splitlines()
    data = dict(ln[2:].split(" ", 1) for ln in lines if ln.startswith("- "))
    return data, next(ln for ln in lines if ln.startswith(("ok", "err")))


def test_the_simulated_bench_turns_the_table_and_sets_the_chamber(sim, gyroctl, tmp_path):
    """`emu rate` moves the plant's input rate, which the rate output then reads; `emu
    ambient` moves the chamber along its edge; a bad move is refused and changes
    nothing."""
    wait_locked(gyroctl, sim)
    _, ok = emu(gyroctl, sim, "emu rate 30 0.05")
    assert ok.startswith("ok rate 30 edge_s 0.05 t_s ")
    _, ok = emu(gyroctl, sim, "emu ambient 35 1000")
    t_move = float(ok.split()[-1])
    for bad, code in (("emu rate 20000", "err RANGE"), ("emu ambient x", "err VALUE"),
                      ("emu rate 10 0", "err RANGE"), ("emu tilt 3", "err ARGS")):
        assert emu(gyroctl, sim, bad)[1].startswith(code), bad
    time.sleep(0.3)
    out = tmp_path / "table.csv"
    r = ctl(gyroctl, sim, "log", "rate_dps", "rate_valid", "--rate", "100", "--duration", "0.5",
            "--out", str(out))
    assert r.returncode == 0, r.stderr
    rows = [row for row in csv.reader(ln for ln in open(out) if not ln.startswith("#"))][1:]
    rates = [float(x[1]) for x in rows if x[2] == "1"]
    assert len(rates) > 40 and abs(sum(rates) / len(rates) / 30.0 - 1.0) < 0.01
    fig, _ = emu(gyroctl, sim, "emu")
    assert float(fig["rate_dps"]) == 30.0
    # 25 -> 35 degC over 1000 s: at 1/100 K per second of the session since the move.
    moved = float(fig["ambient_c"]) - 25.0
    assert moved == pytest.approx((float(fig["t_s"]) - t_move) / 100.0, abs=1e-3)


def test_an_unpaced_session_runs_faster_than_real_time(gyro_sim, gyroctl, tmp_path):
    """--pace 0: gyro time runs as fast as the simulator does, and the session still
    answers. The release build runs about 50x real time on one core; the sanitizer
    build under a loaded CI read 2.9x, so faster than real time is judged as over 1.5x
    (a paced session, --pace 1, stays at or under 1x)."""
    scen = os.path.join(os.environ.get("GYRO_SCENARIOS", ""), "startup.json")
    if not os.path.exists(scen):
        pytest.skip("GYRO_SCENARIOS not set")
    link = str(tmp_path / "gyro.pty")
    proc = subprocess.Popen([gyro_sim, "--scenario", scen, "--duration", "3600", "--quiet",
                             "--pace", "0", f"--uart-pty={link}"], stdout=subprocess.PIPE,
                            text=True)
    try:
        assert proc.stdout.readline().startswith("pty ")
        t0 = float(emu(gyroctl, link, "emu")[0]["t_s"])
        wall0 = time.time()
        time.sleep(1.0)
        fig, _ = emu(gyroctl, link, "emu")
        assert float(fig["pace"]) == 0.0
        assert (float(fig["t_s"]) - t0) / (time.time() - wall0) > 1.5
    finally:
        proc.terminate()
        proc.wait(timeout=10)
