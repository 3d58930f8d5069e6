"""gyroctl_bridge against a fake gyroctl on PATH that records its arguments (the real
tool is written separately; this pins the command-line contract)."""
import json
import os
import stat

import pytest

from gyrotools import gyroctl_bridge
from gyrotools.gyroctl_bridge import GyroctlError

FAKE = """#!/usr/bin/env python3
import json, os, sys
with open(os.environ["FAKE_GYROCTL_LOG"], "a") as fh:
    fh.write(json.dumps(sys.argv[1:]) + "\\n")
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


def test_sets_all_four_terms_then_saves(fake_gyroctl):
    cmds = gyroctl_bridge.write_bias_coeffs("/dev/ttyUSB0", [58.533, 34.59])
    assert fake_gyroctl() == [
        ["--port", "/dev/ttyUSB0", "set", "rate.bias_c0_dps", "58.533"],
        ["--port", "/dev/ttyUSB0", "set", "rate.bias_c1_dps_per_deg", "34.59"],
        ["--port", "/dev/ttyUSB0", "set", "rate.bias_c2_dps_per_deg2", "0"],
        ["--port", "/dev/ttyUSB0", "set", "rate.bias_c3_dps_per_deg3", "0"],
        ["--port", "/dev/ttyUSB0", "save"],
    ]
    assert len(cmds) == 5 and cmds[0][0].endswith("gyroctl")


def test_values_keep_float32_precision(fake_gyroctl):
    gyroctl_bridge.write_bias_coeffs("COM3", [1.0 / 3.0, -2.5e-7, 12345.678901, 0.0])
    vals = [c[4] for c in fake_gyroctl()[:4]]
    assert vals == ["0.333333333", "-2.5e-07", "12345.6789", "0"]


def test_a_refused_set_stops_before_save(fake_gyroctl, monkeypatch):
    monkeypatch.setenv("FAKE_GYROCTL_FAIL_ON", "rate.bias_c2_dps_per_deg2")
    with pytest.raises(GyroctlError, match=r"set rate.bias_c2_dps_per_deg2 0 failed \(exit 3\): "
                                           r"ERR range.*already set live \(not saved\): "
                                           r"rate.bias_c0_dps, rate.bias_c1_dps_per_deg"):
        gyroctl_bridge.write_bias_coeffs("p", [1.0, 2.0])
    assert all("save" not in c for c in fake_gyroctl())
    assert len(fake_gyroctl()) == 3


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
