"""fields: the rate-invalid reasons' names match the firmware's bits, and their time in a
log is counted per reason."""

import os
import re

import numpy as np
import pytest

from gyrotools import fields

HEADER = os.path.join(os.path.dirname(__file__), "..", "..", "..", "firmware", "gyro",
                      "rate_valid.h")


def test_reason_names_are_the_firmwares_bits():
    with open(HEADER, encoding="utf-8") as fh:
        text = fh.read()
    bits = {int(b): n for n, b in re.findall(r"#define RATE_INVALID_(\w+) \(1u << (\d+)\)", text)}
    kinds = int(re.search(r"#define RATE_INVALID_KINDS (\d+)u", text).group(1))
    assert len(bits) == kinds == len(fields.RATE_INVALID)
    assert tuple(bits[k] for k in range(kinds)) == fields.RATE_INVALID


def test_invalid_time_per_reason():
    t = np.arange(10) * 0.5
    r = np.array([1, 1, 0, 0, 128, 128 | 256, 0, 0, 0, 4])
    got = fields.invalid_time_s(t, r)
    assert got == pytest.approx({"MODE": 1.0, "THERMO_RANGE": 1.0, "THERMO_SLEW": 0.5,
                                 "SETTLING": 0.5})
    assert fields.invalid_time_s(t[:1], r[:1]) == {}
