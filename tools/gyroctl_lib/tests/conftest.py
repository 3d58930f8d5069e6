"""pytest set-up: import gyroctl_lib from tools/, locate the C helper programs.

ctest passes their paths in the environment (tools/gyroctl_lib/CMakeLists.txt):
    TLM_VECTORS   tlm-vectors (firmware telemetry encoder/receiver as a program)
    FW_PTY_HOST   tests/e2e/fw_pty_host (the real application behind a pty)
    GYRO_SIM      host_sim/gyro-sim (the application on the plant, --uart-pty)
Run by hand from a configured tree, e.g.
    TLM_VECTORS=build/host/tools/gyroctl_lib/tlm-vectors \
    FW_PTY_HOST=build/host/tests/fw_pty_host python3 -m pytest tools/gyroctl_lib/tests
"""
import os
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
