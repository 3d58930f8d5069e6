#!/usr/bin/env python3
"""Write the seed inputs of the fuzz harnesses into tests/fuzz/corpus/<harness>/.

Seeds give libFuzzer a start inside the interesting grammar (commands, numbers, valid
parameter images built from the layout in firmware/params/param_store.h); crash inputs
found later are kept beside them as regression inputs (tools/run-fuzz)."""
import binascii
import os
import struct

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


def image(seq, records, fmt=1, layout=1):
    hdr = struct.pack("<IHHIII", 0x4D524750, fmt, layout, 0x000100, seq, len(records))
    body = hdr + b"".join(struct.pack("<HBBI", rid, typ, 0, val) for rid, typ, val in records)
    return body + struct.pack("<II", binascii.crc32(body) & 0xFFFFFFFF, 0x5AFEC0DE)


def f32(x):
    return struct.unpack("<I", struct.pack("<f", x))[0]


SLOT = 1024
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
