"""gyro-allan's outputs for users: the IEEE Std 952 coefficients with units in
allan.json, and the Kalibr IMU file (--imu-yaml) in SI units, against noise of known
coefficients; what is written when K is not in the record; the fit is drawn and read
only where it describes the data."""
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest
import synth

from gyrotools import allan

TOOLS = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
FS = 100.0
D2R = math.pi / 180.0


def _yaml(text):
    """key: value pairs of the flat file (comments dropped), YAML's .nan as NaN."""
    out = {}
    for line in text.splitlines():
        body = line.split("#", 1)[0].strip()
        if body:
            k, _, v = body.partition(":")
            v = v.strip()
            out[k.strip()] = math.nan if v.lower() == ".nan" else (v if k == "rostopic" else float(v))
    return out


def test_white_and_rate_random_walk_in_si():
    n_dph, k_dph_rth = 5.0, 20.0
    n = 2 ** 20
    x = synth.white_dps(n, FS, n_dph, np.random.default_rng(1000)) + \
        synth.rrw_dps(n, FS, k_dph_rth, np.random.default_rng(2000))
    res = allan.analyse(x, FS, include_rrw=True)
    ieee = allan.ieee952(res)
    assert set(ieee) == {"Q", "N", "B", "K", "R"}
    assert ieee["N"]["unit"] == "deg/sqrt(h)"
    assert ieee["N"]["value"] == pytest.approx(n_dph / 60, rel=0.02)
    assert ieee["K"]["unit"] == "deg/h/sqrt(h)"
    assert ieee["K"]["value"] == pytest.approx(k_dph_rth, rel=0.25)
    y = _yaml(allan.kalibr_yaml(res, ieee, FS, "synthetic"))
    # deg/h/rtHz -> rad/s/rtHz; deg/h/rt(h) = deg/h/rt(s) / 60 -> rad/s^2/rtHz
    assert y["gyroscope_noise_density"] == pytest.approx(n_dph / 3600 * D2R, rel=0.02)
    assert y["gyroscope_random_walk"] == pytest.approx(k_dph_rth / 60 / 3600 * D2R, rel=0.25)
    assert y["update_rate"] == FS and y["rostopic"] == "/imu0"
    assert math.isnan(y["accelerometer_noise_density"]) and math.isnan(y["accelerometer_random_walk"])


def test_white_noise_fits_and_k_is_an_upper_bound():
    x = synth.white_dps(2 ** 17, FS, 5.0, np.random.default_rng(4))
    res = allan.analyse(x, FS)
    ok = allan.fit_agreement(res) & res.fit_mask
    assert ok.sum() >= 0.85 * res.fit_mask.sum()  # a fit that describes the data
    ieee = allan.ieee952(res)
    assert ieee["K"]["value"] is None and "not observable" in ieee["K"]["source"]
    assert ieee["R"]["value"] is None
    text = allan.kalibr_yaml(res, ieee, FS, "synthetic")
    assert "UPPER BOUND" in text
    t_max, a_max = res.curve.tau_s[-1], res.curve.adev_dph[-1]
    assert _yaml(text)["gyroscope_random_walk"] == pytest.approx(
        a_max / 3600 * math.sqrt(3 / t_max) * D2R, rel=1e-5)


def test_a_fit_that_misses_is_not_read():
    """White noise whose level halves at 1 s (the static_allan shape): no three-term
    sum follows it, and B is not given as if it did."""
    rng = np.random.default_rng(5)
    n = 100 * 1310
    fast = synth.white_dps(n, FS, 40.0, rng)
    slow = np.repeat(synth.white_dps(n // 100, 1.0, 20.0, rng), 100)
    res = allan.analyse(fast - np.convolve(fast, np.ones(100) / 100, "same") + slow, FS)
    ieee = allan.ieee952(res)
    ok = allan.fit_agreement(res) & res.fit_mask
    print(f"fit inside at {ok.sum()} of {res.fit_mask.sum()} taus; B {ieee['B']}")
    assert ok.sum() < 0.7 * res.fit_mask.sum()
    assert ieee["B"]["value"] is None and "misses" in ieee["B"]["source"]


def test_command_writes_json_and_yaml(tmp_path):
    x = synth.white_dps(2 ** 14, FS, 5.0, np.random.default_rng(6))
    csv = tmp_path / "log.csv"
    synth.write_log(csv, {"t_s": np.arange(x.size) / FS, "rate_dps": x})
    yml = tmp_path / "sub" / "imu.yaml"
    r = subprocess.run([sys.executable, os.path.join(TOOLS, "gyro-allan"), str(csv), "--out",
                        str(tmp_path / "a"), "--imu-yaml", str(yml)], capture_output=True,
                       text=True, env={**os.environ, "MPLBACKEND": "Agg"})
    assert r.returncode == 0, r.stderr
    doc = json.load(open(tmp_path / "a" / "allan.json"))
    assert doc["ieee952"]["N"]["value"] == pytest.approx(5.0 / 60, rel=0.1)
    assert _yaml(yml.read_text())["update_rate"] == FS
    r = subprocess.run([sys.executable, os.path.join(TOOLS, "gyro-allan"), str(csv), "--out",
                        str(tmp_path / "a"), "--imu-yaml", "/proc/nope/imu.yaml"],
                       capture_output=True, text=True, env={**os.environ, "MPLBACKEND": "Agg"})
    assert r.returncode == 2 and "Traceback" not in r.stderr
