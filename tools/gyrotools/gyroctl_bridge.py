"""Write calibration coefficients to the gyro through the `gyroctl` command-line tool.

Contract with gyroctl (the UART tuning client, tools/gyroctl), one process per command:

    gyroctl --port PORT set rate.bias_c0_dps VALUE
    gyroctl --port PORT set rate.bias_c1_dps_per_deg VALUE
    gyroctl --port PORT set rate.bias_c2_dps_per_deg2 VALUE
    gyroctl --port PORT set rate.bias_c3_dps_per_deg3 VALUE
    gyroctl --port PORT save

Exit status 0 means the gyro accepted the command; anything else is a failure whose
reason is on stderr. The parameter names are those of the firmware's parameter list
(bias polynomial B(P) = c0 + c1 P + c2 P^2 + c3 P^3, deg/s, P = drive phase in deg,
thesis 7.3.2). All four terms are always written, unused orders as 0, so a term of an
earlier, higher-order calibration cannot linger. `save` is sent only after every `set`
succeeded; on a failure the gyro keeps the values already set live (not saved to flash:
a power cycle restores the stored ones) and the error says which.

gyroctl is looked up as $GYROCTL, then `gyroctl` on PATH, then tools/gyroctl next to
this package.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess

from .errors import InputError

BIAS_PARAMS = ("rate.bias_c0_dps", "rate.bias_c1_dps_per_deg",
               "rate.bias_c2_dps_per_deg2", "rate.bias_c3_dps_per_deg3")


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


def write_params(port, values, gyroctl=None, timeout_s=30.0):
    """Set each parameter of values ({name: number}, in order) with gyroctl, then save.

    Returns the list of commands run. Raises GyroctlError (an InputError) before running
    anything if the input is invalid, and on the first command that fails (naming what
    was already set live but not saved).
    """
    if not isinstance(port, str) or not port.strip():
        raise GyroctlError("no serial port given")
    items = [(str(k), float(v)) for k, v in values.items()]
    if not items:
        raise GyroctlError("nothing to write")
    bad = [k for k, v in items if not math.isfinite(v)]
    if bad:
        raise GyroctlError(f"non-finite value for {', '.join(bad)}")
    exe = gyroctl or find_gyroctl()
    done = []
    for name, value in items:
        cmd = [exe, "--port", port, "set", name, format_value(value)]
        try:
            _run(cmd, timeout_s)
        except GyroctlError as e:
            live = ", ".join(c[4] for c in done) or "none"
            raise GyroctlError(f"{e}; already set live (not saved): {live}") from None
        done.append(cmd)
    cmd = [exe, "--port", port, "save"]
    _run(cmd, timeout_s)
    done.append(cmd)
    return done


def write_bias_coeffs(port, coeffs, gyroctl=None, timeout_s=30.0):
    """Set rate.bias_c0..c3 to coeffs (ascending, 1 to 4 values, rest 0), then save."""
    coeffs = [float(c) for c in coeffs]
    if not 1 <= len(coeffs) <= len(BIAS_PARAMS):
        raise GyroctlError(f"{len(coeffs)} bias coefficients; expected 1 to {len(BIAS_PARAMS)}")
    if not all(math.isfinite(c) for c in coeffs):
        raise GyroctlError(f"non-finite bias coefficient in {coeffs}")
    coeffs = coeffs + [0.0] * (len(BIAS_PARAMS) - len(coeffs))
    return write_params(port, dict(zip(BIAS_PARAMS, coeffs)), gyroctl, timeout_s)
