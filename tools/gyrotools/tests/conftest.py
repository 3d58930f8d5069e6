"""Test set-up: make `gyrotools` and the `synth` helpers importable, and run the
command-line scripts in-process (fast) with their exit status and output captured."""
import os
import runpy
import sys

import pytest

TESTS = os.path.dirname(os.path.abspath(__file__))
TOOLS = os.path.dirname(os.path.dirname(TESTS))
for p in (TOOLS, TESTS):
    if p not in sys.path:
        sys.path.insert(0, p)
os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture
def run_script(capsys, monkeypatch):
    """run_script("gyro-allan", [args]) -> (exit status, stdout, stderr)."""
    def run(name, args):
        path = os.path.join(TOOLS, name)
        monkeypatch.setattr(sys, "argv", [path] + [str(a) for a in args])
        try:
            runpy.run_path(path, run_name="__main__")
            code = 0
        except SystemExit as e:
            code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
        out = capsys.readouterr()
        return code, out.out, out.err
    return run


@pytest.fixture
def tools_dir():
    return TOOLS
