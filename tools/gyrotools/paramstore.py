"""Parameter-store images (firmware/params/param_store.h, format 1) as bytes: the layout
the firmware writes to flash and reads back at boot, for tools that must make one (the
emulated board's factory image, tools/gen_factory_store.py; the fuzz seeds,
tools/gen-fuzz-seeds.py). The firmware's own loader checks every image it reads."""

import struct
import zlib

MAGIC = 0x4D524750
FORMAT = 1
COMMIT = 0x5AFEC0DE
TYPE_CODE = {"F32": 0, "U32": 1, "ENUM": 2}  # param_type_t (params.h)


def image(seq, records, fmt=FORMAT, layout=1, fw_version=0x000100):
    """Header, records [(id, type code, value bits)], CRC-32 and commit word."""
    hdr = struct.pack("<IHHIII", MAGIC, fmt, layout, fw_version, seq, len(records))
    body = hdr + b"".join(struct.pack("<HBBI", rid, typ, 0, val) for rid, typ, val in records)
    return body + struct.pack("<II", zlib.crc32(body), COMMIT)
