#!/usr/bin/env python3
"""Write the seed inputs of the fuzz harnesses into tests/fuzz/corpus/<harness>/.

Seeds give libFuzzer a start inside the interesting grammar (commands, numbers, valid
parameter images built from the layout in firmware/params/param_store.h, parameter-set
files written by tools/gyrotools/paramset.py); crash inputs
found later are kept beside them as regression inputs (tools/run-fuzz)."""
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gyrotools import paramset  # noqa: E402
from gyrotools.paramstore import image  # noqa: E402

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "fuzz", "corpus")


def put(harness, name, data):
    d = os.path.join(ROOT, harness)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "seed-" + name), "wb") as f:
        f.write(data)


CLI = {
    "session": b"\x01help\nlist\nlist drive.\nget drive.freq_hz\nset drive.freq_hz 1500.5\n"
               b"set drive.amp_kp 1 drive.amp_ki 140\ndiff\nsave\nsave\ndefaults\nload\nversion\n",
    "running": b"\x20set drive.mode 1\nsave\nset drive.freq_hz 1e999\nset rate.lpf_order 5\n"
               b"set sys.fs_hz 1\nset demod.mu_sense nan\nload\n",
    "bytewise": b"\x01\tget   tlm.rate_hz \r\nset tlm.rate_hz 250\rset drive.dc_bias_v 13 drive.u_max_v 12\r\n",
    "garbage": b"\x31" + bytes(range(256)) + b"\nget sys.fs_hz\n" + b"x" * 130 + b"\nlist rate\n",
    # console mode (byte 0 bit 2): editing keys, escape sequences, Up, switching back
    "console": b"\x05get tlm.rate_hx\x7fz\r\n\x1b[A\r\x08\x08\x1b[1;5Dset tlm.rate_hz 250\x15"
               b"list drive.\x03\x1bOA\r\x1b[3~\x1bx" + b"y" * 130 + b"\r \t \rconsole off\r\nversion\n",
    "console-switch": b"\x01console on\r\nhelp\r\x1b[Cdiff\x1b[\rconsole\rconsole bad\r"
                      b"get sys.fs_hz\x00\xff\r\nconsole off\rget sys.fs_hz\x7f\n",
}
for k, v in CLI.items():
    put("fuzz_cli", k, v)

for i, s in enumerate([b"1489.9", b"-1.5e-7", b"3.4028235e38", b"1e999", b"1e-39", b"nan",
                       b"0x10", b".5", b"1.00000005960464477539062500", b"4294967295",
                       b"4294967296", b"+0.0e+0", b"340282356779733661637539395458142568448"]):
    put("fuzz_numparse", "%02d" % i, s)


def f32(x):
    return struct.unpack("<I", struct.pack("<f", x))[0]


SLOT = 2048  # tests/fuzz/fuzz_param_store.c SECTOR: an image of every parameter fits
recs_a = [(0x0101, 0, f32(1500.0)), (0x0303, 2, 6), (0x0501, 1, 250), (0x7777, 0, 0)]
recs_b = [(0x0101, 0, f32(1600.0)), (0x0103, 0, f32(9.0)), (0x0102, 1, 1), (0x0501, 1, 250)]


def slots(a, b):
    def pad(x):
        return x + b"\xff" * (SLOT - len(x))

    return pad(a) + pad(b)


put("fuzz_param_store", "two-valid", b"\x00" + slots(image(1, recs_a), image(2, recs_b)))
put("fuzz_param_store", "one-valid", b"\x02" + slots(image(7, recs_b), b""))
put("fuzz_param_store", "repair", b"\x01" + slots(image(1, recs_a)[:-8], image(3, recs_b)[:-8]))
put("fuzz_param_store", "wrap", b"\x00" + slots(image(0xFFFFFFF0, recs_a), image(3, recs_b)))

# Parameter sets (docs/param-set.md), written by gyrotools.paramset from the table: a
# complete set at the defaults, a partial one with meta, and the same broken in the ways
# the reader refuses (checksum, duplicate, kinds of number).

TABLE = paramset.load_table()
SETTABLE = [d for d in TABLE.values() if d.settable]
complete = paramset.from_values([(d.name, d.default) for d in SETTABLE])
put("fuzz_param_set", "complete", paramset.dumps(complete).encode())
first_f32 = next(d for d in SETTABLE if d.type == "F32")
first_u32 = next(d for d in SETTABLE if d.type == "U32")
partial = paramset.from_values([(first_u32.name, int(first_u32.default)), (first_f32.name, first_f32.default)],
                               meta={"part": "SN 17", "notes": ["seed", {"\u00b5": 1.5e-3}], "date": None},
                               firmware="0.1.0")
text = paramset.dumps(partial)
put("fuzz_param_set", "partial", text.encode())
crc = text.split('"crc32": "')[1][:10]
put("fuzz_param_set", "bad-crc", text.replace(crc, "0x%08x" % (int(crc, 16) ^ 0x80)).encode())
line = text.split("\n")[text.split("\n").index('  "params": [') + 1]
put("fuzz_param_set", "duplicate", text.replace(line, line + "\n" + line).encode())
numbers = text.replace(f'"value": {int(first_u32.default)}', '"value": 1.5e0').replace(
    paramset.format_f32(first_f32.default), "-0.0e-0")
put("fuzz_param_set", "numbers", numbers.encode())
