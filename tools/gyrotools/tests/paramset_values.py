"""Parameter values for tests of parameter sets (tools/gyrotools/tests/test_paramset.py,
tools/gyroctl_lib/tests/test_load_params.py)."""

import struct

from gyrotools import paramset as P


def nudged(d):
    """A value near the default but not it, with a float pattern no short decimal gives
    (F32), or the next integer."""
    if d.type == "ENUM":
        return [c for c in d.choices if c != d.default][-1]
    if d.type == "U32":
        return int(d.default) + 1 if d.default < d.max else int(d.default) - 1
    base = d.default * 1.0009765 if d.default else d.min + (d.max - d.min) * 0.3137
    for x in (base, d.default * 0.999, (d.min + d.max) / 2):
        b = struct.unpack("<I", struct.pack("<f", P.f32(x)))[0]
        for c in (b + 1, b - 1):
            v = struct.unpack("<f", struct.pack("<I", c))[0]
            if v != P.f32(d.default) and P.f32(d.min) <= v <= P.f32(d.max) and abs(v) >= P.F32_MIN_NORMAL:
                return v
    raise AssertionError(f"no value to nudge {d.name} to")
