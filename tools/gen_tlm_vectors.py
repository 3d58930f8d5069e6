#!/usr/bin/env python3
"""Reference CRC-16/CCITT-FALSE values for the telemetry frames (firmware/comm/tlm_frame).

Writes tests/vectors/tlm_crc16.csv: one row per test message,
    len, start, step, crc
where the message is bytes (start + step * i) mod 256 for i = 0 .. len-1 and crc is
binascii.crc_hqx(message, 0xFFFF) - Python's CRC-CCITT (polynomial 0x1021, MSB first),
started from 0xFFFF: the CRC-16/CCITT-FALSE of the frame format. Used by
tests/unit/test_tlm_frame.c.

Deterministic; re-run with
    python3 tools/gen_tlm_vectors.py
and commit the output.
"""
import binascii
import pathlib

OUT = pathlib.Path(__file__).resolve().parent.parent / "tests" / "vectors"


def message(n, start, step):
    return bytes((start + step * i) % 256 for i in range(n))


def main():
    rows = []
    # every length through two COBS blocks, then a few long ones
    for n in list(range(0, 64)) + [127, 128, 253, 254, 255, 256, 300, 508, 509, 560]:
        for start, step in ((0, 1), (0xA5, 37), (0xFF, 0), (0, 0), (1, 254)):
            rows.append((n, start, step, binascii.crc_hqx(message(n, start, step), 0xFFFF)))
    path = OUT / "tlm_crc16.csv"
    with open(path, "w", encoding="ascii") as f:
        f.write("# len, start, step, crc16_ccitt_false  (binascii.crc_hqx(msg, 0xFFFF); "
                "msg[i] = (start + step*i) mod 256; tools/gen_tlm_vectors.py)\n")
        for r in rows:
            f.write("%d,%d,%d,%d\n" % r)
    print(f"wrote {path} ({len(rows)} rows)")


if __name__ == "__main__":
    main()
