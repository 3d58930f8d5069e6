"""The Python receiver (gyroctl_lib.frames) against the firmware's encoder and the C
receiver: streams written by the firmware's own encoder (tlm-vectors make) decode to
exactly the records the ISR was given; on damaged and truncated copies the Python
receiver reaches the same verdict as the C one (tlm-vectors decode), counter for counter
and record for record, and never delivers a wrong record."""

import json
import random
import struct
import subprocess

import pytest

from gyroctl_lib import frames

# ---- primitives ----

def test_crc_check_value():
    assert frames.crc16(b"123456789") == 0x29B1
    assert frames.crc16(b"") == 0xFFFF


# the published COBS examples (as in tests/unit/test_tlm_frame.c)
COBS_EXAMPLES = [
    (b"", b"\x01"),
    (b"\x00", b"\x01\x01"),
    (b"\x00\x00", b"\x01\x01\x01"),
    (b"\x00\x11\x00", b"\x01\x02\x11\x01"),
    (b"\x11\x22\x00\x33", b"\x03\x11\x22\x02\x33"),
    (b"\x11\x22\x33\x44", b"\x05\x11\x22\x33\x44"),
    (b"\x11\x00\x00\x00", b"\x02\x11\x01\x01\x01"),
    (bytes(range(1, 255)), b"\xff" + bytes(range(1, 255))),
    (bytes(range(0, 255)), b"\x01\xff" + bytes(range(1, 255))),
    (bytes(range(1, 256)), b"\xff" + bytes(range(1, 255)) + b"\x02\xff"),
    (bytes(range(2, 256)) + b"\x00", b"\xff" + bytes(range(2, 256)) + b"\x01\x01"),
    (bytes(range(3, 256)) + b"\x00\x01", b"\xfe" + bytes(range(3, 256)) + b"\x02\x01"),
]


@pytest.mark.parametrize("raw,enc", COBS_EXAMPLES)
def test_cobs_examples(raw, enc):
    assert frames.cobs_encode(raw) == enc
    assert frames.cobs_decode(enc) == raw


def test_cobs_round_trip_and_rejects():
    rng = random.Random(3)
    for n in range(0, 600, 7):
        for density in (0.0, 0.1, 0.5):
            raw = bytes(0 if rng.random() < density else rng.randrange(1, 256) for _ in range(n))
            enc = frames.cobs_encode(raw)
            assert 0 not in enc and len(enc) <= frames.cobs_max(n)
            assert frames.cobs_decode(enc, cap=1000) == raw
    assert frames.cobs_decode(b"\x03\x11") is None
    assert frames.cobs_decode(b"\x03\x11\x00") is None
    assert frames.cobs_decode(b"\x05\x01\x02\x03\x04\x01", cap=4) is None


def test_header_built_by_hand():
    payload = struct.pack("<BIIIHIIB", 1, 7, 50000, 50, 10, 3, 1, 2) + b"\x01\x04tick" + b"\x00\x08rate_dps"
    got = []
    d = frames.Decoder(on_header=got.append)
    d.feed(frames.to_wire(frames.seal(frames.TYPE_HEADER, 0, payload)))
    assert len(got) == 1
    lay = got[0]
    assert (lay.stream_id, lay.fs_hz, lay.decim, lay.rec_per_frame, lay.lost, lay.dropped) == (7, 50000, 50, 10, 3, 1)
    assert lay.fields == [("tick", frames.T_U32), ("rate_dps", frames.T_F32)]
    assert lay.rate_hz == 1000.0
    # a malformed variant (name with '-') is counted, not delivered
    d.feed(frames.to_wire(frames.seal(frames.TYPE_HEADER, 1, payload.replace(b"rate_dps", b"rate-dps"))))
    assert len(got) == 1 and d.stats.bad_format == 1


def test_header_32_fields():
    """The widest header (32 fields with 31-byte names: a raw frame of FRAME_MAX bytes)
    and a record whose fields past the 16th decode in place; 33 fields are refused."""
    def header(names):
        fixed = struct.pack("<BIIIHIIB", 1, 7, 50000, 50, 1, 0, 0, len(names))
        return fixed + b"".join(bytes([i & 1, len(n)]) + n for i, n in enumerate(names))
    names = [(b"%c%d" % (97 + i // 10, i % 10)).ljust(frames.NAME_MAX, b"x") for i in range(frames.FIELDS_MAX)]
    raw = frames.seal(frames.TYPE_HEADER, 0, header(names))
    assert len(raw) == frames.FRAME_MAX
    heads, data = [], []
    d = frames.Decoder(on_header=heads.append, on_data=data.append)
    d.feed(frames.to_wire(raw))
    assert len(heads) == 1 and len(heads[0].fields) == 32
    assert heads[0].fields[31] == ("d1" + "x" * 29, frames.T_U32)
    words = [0xA5000000 | i for i in range(32)]
    d.feed(frames.to_wire(frames.seal(frames.TYPE_DATA, 1, struct.pack("<HIB", 7, 0, 1) + struct.pack("<32I", *words))))
    assert len(data) == 1 and list(data[0].words[0]) == words
    d.feed(frames.to_wire(frames.seal(frames.TYPE_HEADER, 2, header([b"a%d" % i for i in range(33)]))))
    assert len(heads) == 1 and d.stats.bad_format == 1


# ---- against the firmware's encoder ----

@pytest.fixture(scope="module")
def vectors(tlm_vectors, tmp_path_factory):
    out = tmp_path_factory.mktemp("tlm")
    subprocess.run([tlm_vectors, "make", str(out)], check=True)
    stream = (out / "stream.bin").read_bytes()
    expected = json.loads((out / "expected.json").read_text())
    return stream, expected


def _truth(expected):
    """{(stream_id, index): words} of every record the ISR took."""
    t = {}
    for s in expected["streams"]:
        for rec in s["records"]:
            t[(s["stream_id"], rec[0])] = tuple(rec[1:])
    return t


def _collect(data):
    lines, headers, recs = [], [], []

    def on_data(fr):
        for r, w in enumerate(fr.words):
            recs.append((fr.layout.stream_id, fr.first_rec + r, tuple(w)))

    d = frames.Decoder(lines.append, headers.append, on_data)
    d.feed(data)
    return d, lines, headers, recs


def test_decodes_encoder_stream_exactly(vectors):
    stream, expected = vectors
    d, lines, headers, recs = _collect(stream)
    assert lines == expected["lines"] + expected["trailer"]
    truth = _truth(expected)
    assert all(truth[(sid, i)] == w for sid, i, w in recs)
    for s in expected["streams"]:
        mine = [r for r in recs if r[0] == s["stream_id"]]
        assert len(mine) == s["taken"]  # records framed; `lost` never left the ISR
        assert len(s["records"]) == s["taken"] + s["lost"]
        hs = [h for h in headers if h.stream_id == s["stream_id"]]
        assert hs and all(h.fields == [tuple(f) for f in s["fields"]] for h in hs)
        assert hs[0].decim == s["decim"] and hs[0].fs_hz == s["fs_hz"]
    # stream 3 had its background loop stalled: records lost at the source, counted
    assert expected["streams"][2]["lost"] > 0
    assert d.stats.rec_missing == sum(s["lost"] for s in expected["streams"])
    assert (d.stats.corrupt, d.stats.bad_format, d.stats.no_layout, d.stats.seq_missing) == (0, 0, 0, 0)
    assert d.stats.headers + d.stats.data == sum(s["frames"] for s in expected["streams"])
    # the float fields read back as the values the ISR saw
    s1 = expected["streams"][0]
    values = [fr for fr in recs if fr[0] == s1["stream_id"]][:3]
    assert all(struct.unpack("<f", struct.pack("<I", w[0]))[0] == pytest.approx(0.001 * w[4] - 3.0, rel=1e-6)
               for _, _, w in values)


def _c_verdict(tlm_vectors, tmp_path, data):
    p = tmp_path / "damaged.bin"
    p.write_bytes(data)
    out = subprocess.run([tlm_vectors, "decode", str(p)], check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def _fnv(h, w):
    for i in range(4):
        h ^= (w >> (8 * i)) & 0xFF
        h = (h * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return h


def _py_verdict(data):
    d, lines, _, recs = _collect(data)
    h = 1469598103934665603
    for sid, i, w in recs:
        h = _fnv(h, sid)
        h = _fnv(h, i & 0xFFFFFFFF)
        for x in w:
            h = _fnv(h, x)
    v = {k: getattr(d.stats, k) for k in ("lines", "lines_bad", "headers", "data", "corrupt", "bad_format",
                                          "no_layout", "seq_missing", "rec_missing")}
    v.update(records=len(recs), digest=h, line_chars=sum(len(x) for x in lines))
    return v, recs


def _damage(stream, seed):
    rng = random.Random(seed)
    out = bytearray()
    for b in stream:
        r = rng.random()
        if r < 0.0005:
            out.append(b ^ (1 << rng.randrange(8)))   # bit error
        elif r < 0.0008:
            continue                                  # lost byte
        elif r < 0.0011:
            out += bytes(rng.randrange(256) for _ in range(rng.randrange(1, 30)))  # garbage
            out.append(b)
        else:
            out.append(b)
    return bytes(out)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_damage_same_verdict_as_c_never_misread(vectors, tlm_vectors, tmp_path, seed):
    stream, expected = vectors
    data = _damage(stream, seed)
    py, recs = _py_verdict(data)
    assert py == _c_verdict(tlm_vectors, tmp_path, data)
    truth = _truth(expected)
    assert all(truth[(sid, i)] == w for sid, i, w in recs)
    assert py["corrupt"] > 10


def test_truncated_same_verdict_as_c(vectors, tlm_vectors, tmp_path):
    stream, expected = vectors
    rng = random.Random(9)
    for cut in [1, 2, 3, 40, 41, 300] + [rng.randrange(len(stream)) for _ in range(6)]:
        py, recs = _py_verdict(stream[:cut])
        assert py == _c_verdict(tlm_vectors, tmp_path, stream[:cut])
        truth = _truth(expected)
        assert all(truth[(sid, i)] == w for sid, i, w in recs)
