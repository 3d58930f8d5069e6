"""gyroctl_bridge against a fake gyroctl on PATH that records its arguments and the
parameter set it was given (the real tool is tested against the firmware in
tools/gyroctl_lib/tests/test_load_params.py; this pins the command-line contract)."""
import json
import os
import stat

import pytest

from gyrotools import gyroctl_bridge, paramset
from gyrotools.gyroctl_bridge import GyroctlError

FAKE = """#!/usr/bin/env python3
import json, os, sys
with open(os.environ["FAKE_GYROCTL_LOG"], "a") as fh:
    fh.write(json.dumps(sys.argv[1:]) + "\\n")
with open(sys.argv[4]) as f, open(os.environ["FAKE_GYROCTL_LOG"] + ".set", "w") as g:
    g.write(f.read())
fail = os.environ.get("FAKE_GYROCTL_FAIL_ON")
if fail and fail in sys.argv[1:]:
    print("ERR range: value out of range", file=sys.stderr)
    sys.exit(3)
print("OK")
"""


@pytest.fixture
def fake_gyroctl(tmp_path, monkeypatch):
    bindir = tmp_path / "bin"
    bindir.mkdir()
    exe = bindir / "gyroctl"
    exe.write_text(FAKE)
    exe.chmod(exe.stat().st_mode | stat.S_IXUSR)
    log = tmp_path / "calls.jsonl"
    monkeypatch.setenv("PATH", f"{bindir}{os.pathsep}{os.environ['PATH']}")
    monkeypatch.delenv("GYROCTL", raising=False)
    monkeypatch.delenv("FAKE_GYROCTL_FAIL_ON", raising=False)
    monkeypatch.setenv("FAKE_GYROCTL_LOG", str(log))

    def calls():
        if not log.exists():
            return []
        return [json.loads(x) for x in log.read_text().splitlines()]
    return calls


def test_one_load_params_with_all_four_terms(fake_gyroctl, tmp_path):
    cmds = gyroctl_bridge.write_bias_coeffs("/dev/ttyUSB0", [58.533, 34.59])
    (call,) = fake_gyroctl()
    assert call[:3] == ["--port", "/dev/ttyUSB0", "load-params"] and call[4:] == ["--merge"]
    ps = paramset.read(tmp_path / "calls.jsonl.set")
    assert ps.values() == {"rate.bias_c0_dps": paramset.f32(58.533),
                           "rate.bias_c1_dps_per_deg": paramset.f32(34.59),
                           "rate.bias_c2_dps_per_deg2": 0.0,
                           "rate.bias_c3_dps_per_deg3": 0.0}
    assert len(cmds) == 1 and cmds[0][0].endswith("gyroctl")


def test_values_keep_float32_precision(fake_gyroctl, tmp_path):
    gyroctl_bridge.write_bias_coeffs("COM3", [1.0 / 3.0, -2.5e-7, 1234.5678901, 0.0])
    vals = list(paramset.read(tmp_path / "calls.jsonl.set").values().values())
    assert vals == [paramset.f32(x) for x in (1.0 / 3.0, -2.5e-7, 1234.5678901, 0.0)]


def test_a_refusal_is_reported(fake_gyroctl, monkeypatch):
    monkeypatch.setenv("FAKE_GYROCTL_FAIL_ON", "load-params")
    with pytest.raises(GyroctlError, match=r"load-params .* failed \(exit 3\): ERR range"):
        gyroctl_bridge.write_bias_coeffs("p", [1.0, 2.0])


def test_a_value_the_list_refuses_sends_nothing(fake_gyroctl):
    with pytest.raises(GyroctlError, match="rate.bias_c0_dps"):
        gyroctl_bridge.write_bias_coeffs("p", [1e9])
    assert fake_gyroctl() == []


@pytest.mark.parametrize("port, coeffs, msg", [
    ("", [1.0], "no serial port"),
    ("p", [], "0 bias coefficients"),
    ("p", [1, 2, 3, 4, 5], "5 bias coefficients"),
    ("p", [1.0, float("nan")], "non-finite"),
])
def test_invalid_input_runs_nothing(fake_gyroctl, port, coeffs, msg):
    with pytest.raises(GyroctlError, match=msg):
        gyroctl_bridge.write_bias_coeffs(port, coeffs)
    assert fake_gyroctl() == []


def test_lookup_order(fake_gyroctl, monkeypatch, tmp_path):
    assert gyroctl_bridge.find_gyroctl().endswith(os.path.join("bin", "gyroctl"))
    monkeypatch.setenv("GYROCTL", "/opt/x/gyroctl")
    assert gyroctl_bridge.find_gyroctl() == "/opt/x/gyroctl"
    with pytest.raises(GyroctlError, match="cannot run /opt/x/gyroctl"):
        gyroctl_bridge.write_bias_coeffs("p", [1.0])
