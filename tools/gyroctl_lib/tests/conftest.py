"""pytest set-up: import gyroctl_lib from tools/, locate the C helper programs.

ctest passes their paths in the environment (tools/gyroctl_lib/CMakeLists.txt):
    TLM_VECTORS   tlm-vectors (firmware telemetry encoder/receiver as a program)
    FW_PTY_HOST   tests/e2e/fw_pty_host (the real application behind a pty)
    GYRO_SIM      gyro-sim (host_sim/gyro_sim: the application on the plant, --uart-pty)
Run by hand from a configured tree, e.g.
    TLM_VECTORS=build/host/tools/gyroctl_lib/tlm-vectors \
    FW_PTY_HOST=build/host/tests/fw_pty_host python3 -m pytest tools/gyroctl_lib/tests
"""
import os
import subprocess
import sys

import pytest

TOOLS = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
if TOOLS not in sys.path:
    sys.path.insert(0, TOOLS)


def _exe(var):
    path = os.environ.get(var)
    if not path or not os.access(path, os.X_OK):
        pytest.skip(f"${var} not set to a built program (run under ctest)")
    return path


@pytest.fixture(scope="session")
def tlm_vectors():
    return _exe("TLM_VECTORS")


@pytest.fixture(scope="session")
def fw_pty_host():
    return _exe("FW_PTY_HOST")


@pytest.fixture(scope="session")
def gyro_sim():
    return _exe("GYRO_SIM")


@pytest.fixture(scope="session")
def gyroctl():
    return [sys.executable, os.path.join(TOOLS, "gyroctl")]


@pytest.fixture
def sim(gyro_sim, tmp_path):
    """gyro-sim on the startup scenario with its command line on a pty (real time, at
    most 120 s): the pty's path. The part is the ideal preset: these tests check the
    tools and the firmware against the plant's linear figures (the sweep's Q against
    q_drive), which the default part's stroke-dependent drive damping moves by 2 %."""
    scen = os.path.join(os.environ.get("GYRO_SCENARIOS", ""), "startup.json")
    if not os.path.exists(scen):
        pytest.skip("GYRO_SCENARIOS not set")
    link = str(tmp_path / "gyro.pty")
    proc = subprocess.Popen([gyro_sim, "--scenario", scen, "--duration", "120", "--quiet",
                             "--set", "plant.preset=ideal",
                             f"--uart-pty={link}"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline().split()
    if len(line) != 2 or line[0] != "pty":
        proc.kill()
        pytest.fail(f"gyro-sim did not start: {line} {proc.stderr.read()}")
    yield link
    proc.terminate()
    proc.wait(timeout=10)
