"""Write calibration coefficients to the gyro through the `gyroctl` command-line tool.

Contract with gyroctl (the UART tuning client, tools/gyroctl): the values go as a
parameter set (docs/param-set.md, written to a temporary file) in one command,

    gyroctl --port PORT load-params FILE --merge

which stops the drive, sets every value (each echo compared with the file), saves them
to flash and starts the drive again if it ran (tools/gyroctl_lib/load_params.py): safe
on a running gyro, whose firmware refuses `save` while the drive runs. Exit status 0
means the gyro holds the values in flash; anything else is a failure whose reason is on
stderr (the board may then hold part of them in RAM, unsaved, with the drive off:
`gyroctl load` restores flash). The parameter names are those of the firmware's
parameter list (bias polynomial B(P) = c0 + c1 P + c2 P^2 + c3 P^3, deg/s, P = drive
phase in deg, thesis 7.3.2); a name or value the list refuses is refused before
anything is sent. All four bias terms are always written, unused orders as 0, so a term
of an earlier, higher-order calibration cannot linger.

gyroctl is looked up as $GYROCTL, then `gyroctl` on PATH, then tools/gyroctl next to
this package.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import tempfile

from . import paramset, tempcomp
from .errors import InputError

BIAS_PARAMS = tempcomp.BIAS_PARAMS


class GyroctlError(InputError):
    """gyroctl is missing or refused a command."""


def find_gyroctl():
    env = os.environ.get("GYROCTL")
    if env:
        return env
    on_path = shutil.which("gyroctl")
    if on_path:
        return on_path
    sibling = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                           "gyroctl")
    if os.path.isfile(sibling) and os.access(sibling, os.X_OK):
        return sibling
    raise GyroctlError("gyroctl not found ($GYROCTL, PATH, tools/gyroctl)")


def format_value(x):
    """Nine significant digits: round-trips a float32, the firmware's storage type."""
    return f"{x:.9g}"


def _run(cmd, timeout_s):
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s,
                           check=False)
    except FileNotFoundError:
        raise GyroctlError(f"cannot run {cmd[0]}") from None
    except PermissionError:
        raise GyroctlError(f"{cmd[0]} is not executable") from None
    except subprocess.TimeoutExpired:
        raise GyroctlError(f"{' '.join(cmd)}: no answer in {timeout_s:g} s") from None
    if p.returncode != 0:
        why = (p.stderr or p.stdout).strip().splitlines()
        raise GyroctlError(f"{' '.join(cmd[1:])} failed (exit {p.returncode})"
                           + (f": {why[-1]}" if why else ""))
    return p


def write_params(port, values, gyroctl=None, timeout_s=60.0):
    """Write values ({name: number}) into the gyro's flash with gyroctl load-params.

    Returns the list of commands run (one). Raises GyroctlError (an InputError) before
    running anything if the input is invalid (no port, nothing to write, a value that
    is not finite, a name or value the parameter list refuses), and when gyroctl fails.
    """
    if not isinstance(port, str) or not port.strip():
        raise GyroctlError("no serial port given")
    items = [(str(k), float(v)) for k, v in values.items()]
    if not items:
        raise GyroctlError("nothing to write")
    bad = [k for k, v in items if not math.isfinite(v)]
    if bad:
        raise GyroctlError(f"non-finite value for {', '.join(bad)}")
    try:
        ps = paramset.from_values(items, meta={"made_by": "gyrotools.gyroctl_bridge"})
    except paramset.ParamSetError as e:
        raise GyroctlError(str(e)) from None
    exe = gyroctl or find_gyroctl()
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "params.json")
        paramset.write(path, ps)
        cmd = [exe, "--port", port, "load-params", path, "--merge"]
        _run(cmd, timeout_s)
    return [cmd]


def write_bias_coeffs(port, coeffs, gyroctl=None, timeout_s=60.0):
    """Set rate.bias_c0..c3 to coeffs (ascending, 1 to 4 values, rest 0), then save."""
    coeffs = [float(c) for c in coeffs]
    if not 1 <= len(coeffs) <= len(BIAS_PARAMS):
        raise GyroctlError(f"{len(coeffs)} bias coefficients; expected 1 to {len(BIAS_PARAMS)}")
    if not all(math.isfinite(c) for c in coeffs):
        raise GyroctlError(f"non-finite bias coefficient in {coeffs}")
    coeffs = coeffs + [0.0] * (len(BIAS_PARAMS) - len(coeffs))
    return write_params(port, dict(zip(BIAS_PARAMS, coeffs)), gyroctl, timeout_s)
