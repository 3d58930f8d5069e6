"""Parameter sets in Python (gyrotools.paramset, docs/param-set.md): a set written and read
back bit for bit, the checksum against zlib over the canonical lines, the float text,
and every class of bad file refused with the entry named. Parameters are picked from the
table by kind, so the tests hold for any parameter list."""

import json
import struct
import zlib

import pytest
from paramset_values import nudged

from gyrotools import paramset as P

TABLE = P.load_table()


def pick(kind, settable=True):
    for d in TABLE.values():
        if d.type == kind and d.settable == settable:
            return d
    pytest.skip(f"no {'settable' if settable else 'other'} {kind} parameter in the table")


def doc(entries, crc=None, **top):
    """A file of entries [(id, name, value)] with the right checksum (or crc)."""
    lines = []
    for pid, _name, value in entries:
        d = TABLE.get(pid)
        bits = P.f32_bits(value) if d is not None and d.type == "F32" else int(value)
        lines.append("%04x %08x\n" % (pid, bits))
    if crc is None:
        crc = zlib.crc32("".join(lines).encode()) & 0xFFFFFFFF
    root = {"format": "gyro-param-set", "format_version": 1, **top,
            "params": [{"id": f"0x{pid:04x}", "name": n, "value": v} for pid, n, v in entries],
            "crc32": f"0x{crc:08x}"}
    return json.dumps(root)


def refused(text, want):
    with pytest.raises(P.ParamSetError) as e:
        P.parse(text)
    assert want in str(e.value), str(e.value)


def test_round_trip_bit_exact(tmp_path):
    f, u, en = pick("F32"), pick("U32"), pick("ENUM")
    values = {u.name: nudged(u), f.name: nudged(f), en.name: nudged(en)}
    ps = P.from_values(values, meta={"part": "SN 17", "by": "test"})
    path = tmp_path / "part.json"
    P.write(path, ps)
    back = P.read(path)
    assert [e.name for e in back.entries] == list(values)  # file order kept
    got = back.values()
    assert struct.pack("<f", got[f.name]) == struct.pack("<f", values[f.name])
    assert got[u.name] == values[u.name] and got[en.name] == values[en.name]
    assert isinstance(got[u.name], int)
    assert back.meta == {"part": "SN 17", "by": "test"}
    assert back.layout_version == P.layout_version()
    # the text is the layout the firmware writer uses
    text = path.read_text()
    assert text.startswith('{\n  "format": "gyro-param-set",\n  "format_version": 1,\n')
    assert f'    {{"id": "0x{u.id:04x}", "name": "{u.name}", "value": {values[u.name]}}}' in text


def test_checksum_is_zlib_of_the_lines():
    f, u = pick("F32"), pick("U32")
    ps = P.from_values([(f.name, nudged(f)), (u.name, nudged(u))])
    e0, e1 = ps.entries
    text = "%04x %08x\n%04x %08x\n" % (e0.id, struct.unpack("<I", struct.pack("<f", e0.value))[0],
                                       e1.id, e1.value)
    assert P.crc32_of(ps.entries, TABLE) == zlib.crc32(text.encode())
    assert P.crc32_of([], TABLE) == 0
    # the text of the floats does not matter, only their float32 bits
    d = doc([(f.id, f.name, e0.value)])
    assert P.parse(d.replace(json.dumps(e0.value), "%.17g" % e0.value)).entries[0].value == e0.value


@pytest.mark.parametrize("x, text", [(30.0, "30.0"), (1489.9, "1489.9"), (0.349, "0.349"),
                                     (1e-5, "1e-05"), (1e7, "10000000.0"), (1e20, "1e+20"),
                                     (0.1, "0.1"), (-10.0, "-10.0"), (0.0, "0.0"),
                                     (3.4028234663852886e38, "3.4028235e+38")])
def test_float_text(x, text):
    assert P.format_f32(x) == text
    assert P.f32(float(text)) == P.f32(x)


def test_float_text_reads_back():
    for bits in range(0x3F800000, 0x3F800000 + 2000, 7):
        v = struct.unpack("<f", struct.pack("<I", bits))[0]
        t = P.format_f32(v)
        assert P.f32(float(t)) == v and len(t.replace("-", "").replace(".", "")) <= 11


def test_bad_structure():
    f = pick("F32")
    good = doc([(f.id, f.name, nudged(f))])
    refused("{", "not valid JSON")
    refused(good + " x", "not valid JSON")
    refused("[1]", "top level: expected an object")
    refused(json.dumps({"format": "gyro-param-set", "format_version": 1, "params": []}), '"crc32" missing')
    refused(doc([], colour=1), 'unknown key "colour"')
    refused(good.replace('"format_version": 1', '"format_version": 2'), "newer than this reader's (1)")
    refused(good.replace('"format_version": 1', '"format_version": "1"'), "format_version: expected 1")
    refused(good.replace("gyro-param-set", "gyro-param-sets"), 'format: expected "gyro-param-set"')
    refused(doc([], meta=[1]), "meta: expected an object")
    refused(doc([], firmware=1), "firmware: expected a string")
    refused(doc([], layout_version=1.5), "layout_version")
    refused(good.replace('"format_version": 1', '"format_version": 1, "format_version": 1'), "given twice")
    P.parse(doc([], meta={"a": 1}).replace('{"a": 1}', '{"a": 1, "a": 2}'))  # meta is free-form
    refused(good.replace('"params": [', '"params": 7, "x": ['), "unknown key")
    refused(json.dumps({"format": "gyro-param-set", "format_version": 1, "params": 7, "crc32": "0x0"}),
            "params: expected a list")


def test_bad_entries():
    f = pick("F32")
    unused = next(i for i in range(0xFFFF, 0, -1) if i not in TABLE)
    refused(doc([(unused, "x.y", 1.0)]), f"params[0]: unknown id 0x{unused:04x}")
    refused(doc([(f.id, f.name + "x", 1.0)]), "does not match the id's name")
    refused(doc([(f.id, f.name, nudged(f))] * 2), "params[1] (id 0x%04x, %s): the id appears more than once"
            % (f.id, f.name))
    good = doc([(f.id, f.name, nudged(f))])
    refused(good.replace(f'"0x{f.id:04x}"', f'"0x{f.id:03x}"' if f.id < 0x1000 else '"0x1"'), "id: expected")
    refused(good.replace(f'"0x{f.id:04x}"', str(f.id)), "id: expected a 16-bit id")
    refused(good.replace('"value"', '"unit": "V", "value"'), 'unknown key "unit"')
    refused(good.replace(', "value": ' + json.dumps(nudged(f)), ""), '"value" missing')
    ro = [d for d in TABLE.values() if "read-only" in d.flags]
    if ro:
        refused(doc([(ro[0].id, ro[0].name, ro[0].min)]), "read-only")
    np_ = [d for d in TABLE.values() if not d.flags & {"persist", "read-only"}]
    if np_:
        refused(doc([(np_[0].id, np_[0].name, np_[0].min)]), "not persistent")


def test_bad_values():
    f, u, en = pick("F32"), pick("U32"), pick("ENUM")
    refused(doc([(f.id, f.name, f.max * 2 + 1)]), "is out of range: [")
    text = doc([(f.id, f.name, nudged(f))])
    val = json.dumps(nudged(f))
    refused(text.replace(val, "1e39"), "out of range")
    refused(text.replace(val, "1e999"), "not a finite number")
    refused(text.replace(val, "NaN"), "not valid JSON")
    refused(text.replace(val, "1e-41"), "out of range")  # subnormal float32
    for bad in ('"nan"', "null", "true", "[1]", "{}"):
        refused(text.replace(val, bad), "value: expected a number")
    ut = doc([(u.id, u.name, int(u.min))])
    refused(ut.replace(f'"value": {int(u.min)}', '"value": 1.5'), "is not an integer")
    refused(ut.replace(f'"value": {int(u.min)}', '"value": -1'), "out of range")
    refused(ut.replace(f'"value": {int(u.min)}', '"value": 4294967296'), "out of range")
    assert P.parse(ut.replace(f'"value": {int(u.min)}', f'"value": {int(u.min)}.0')).entries[0].value == u.min
    bad = next(c for c in range(33) if c not in en.choices)
    refused(doc([(en.id, en.name, bad)]), "not an allowed choice: one of")


def test_checksum_mismatch():
    f = pick("F32")
    v = nudged(f)
    good = doc([(f.id, f.name, v)])
    crc = json.loads(good)["crc32"]
    refused(good.replace(crc, "0x%08x" % (int(crc, 16) ^ 1)), "checksum mismatch: file edited by hand?")
    edited = P.f32(v * 1.5) if f.min <= v * 1.5 <= f.max else P.f32(v / 1.5)
    refused(good.replace(json.dumps(v), json.dumps(edited)), "checksum mismatch")
    refused(good.replace(crc, crc[:-1]), 'crc32: expected a string "0x%08x"')


def test_writer_checks():
    f = pick("F32")
    with pytest.raises(P.ParamSetError, match="no such parameter"):
        P.from_values({"no.such_param": 1.0})
    with pytest.raises(P.ParamSetError, match="out of range"):
        P.from_values({f.name: f.max * 2 + 1})
    ps = P.from_values({f.name: -0.0}) if f.min <= 0 <= f.max else None
    if ps is not None:
        assert '"value": 0.0}' in P.dumps(ps)  # -0 is written as 0, as the firmware holds it


def test_read_names_the_file(tmp_path):
    with pytest.raises(P.ParamSetError, match="none.json"):
        P.read(tmp_path / "none.json")
    p = tmp_path / "bad.json"
    p.write_text("{}")
    with pytest.raises(P.ParamSetError, match=r"bad.json: top level: \"format\" missing"):
        P.read(p)
