"""Firmware parameter sets (docs/param-set.md): read, check and write the JSON files that
hold a part's calibration, as gyro-sim (--firmware-params, --save-params) and
`gyroctl load-params` use them.

    {"format": "gyro-param-set", "format_version": 1, "layout_version": 5,
     "firmware": "0.1.0", "meta": {...},
     "params": [{"id": "0x0101", "name": "drive.freq_hz", "value": 1489.9}, ...],
     "crc32": "0x1234abcd"}

The checksum is CRC-32/IEEE (zlib.crc32) of the lines "%04x %08x\\n" % (id, bits), one
per entry in file order, bits being the float32 pattern of an F32 value (the value
rounded to float32 first) and the integer of a U32/ENUM value. The parameter table (ids,
names, types, flags, ranges) is read from the source tree's firmware/params/param_list.h
(the parser of tools/gen_params_doc.py), so a file this module accepts is one the
firmware's own reader (host_sim/paramset/param_set.h) accepts too, but for the firmware's
check of the values together (its loop design), which only the firmware can make.

    ps = read("part.json")                     # ParamSetError (an InputError) if bad
    write("part.json", from_values({"drive.cal_q": 35.2, "tlm.rate_hz": 250},
                                   meta={"part": "SN 17"}))
"""

from __future__ import annotations

import dataclasses
import functools
import importlib.util
import json
import math
import os
import re
import struct
import zlib

from .errors import InputError

FORMAT = "gyro-param-set"
FORMAT_VERSION = 1
F32_MAX = 3.4028234663852886e38
F32_LIMIT = 2.0 ** 128 - 2.0 ** 103  # from here on a value rounds to float32 infinity
F32_MIN_NORMAL = 1.1754943508222875e-38
TOP_KEYS = ("format", "format_version", "params", "crc32", "layout_version", "firmware", "meta")
TOP_REQUIRED = 4
ENTRY_KEYS = ("id", "name", "value")
ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
ID_RE = re.compile(r"0[xX][0-9a-fA-F]{4}")
CRC_RE = re.compile(r"0[xX][0-9a-fA-F]{8}")


class ParamSetError(InputError):
    """A parameter set that cannot be taken: the message names the entry and why."""


@dataclasses.dataclass(frozen=True)
class ParamDef:
    """One row of the firmware's parameter table (firmware/params/param_list.h)."""
    id: int
    name: str
    type: str           # "F32", "U32" or "ENUM"
    flags: frozenset    # "persist", "read-only", "live", "restart"
    min: float
    max: float
    default: float
    choices: tuple      # ENUM: the allowed values
    unit: str

    @property
    def settable(self) -> bool:
        """Held by flash and writable: what a parameter set may contain."""
        return "persist" in self.flags and "read-only" not in self.flags


@dataclasses.dataclass
class Entry:
    id: int
    name: str
    value: float | int  # F32: the float32 value (as a Python float); U32/ENUM: int


@dataclasses.dataclass
class ParamSet:
    entries: list
    layout_version: int | None = None
    firmware: str | None = None
    meta: dict = dataclasses.field(default_factory=dict)

    def values(self) -> dict:
        """{name: value} in file order."""
        return {e.name: e.value for e in self.entries}


# ---- the parameter table ----

def _gen_params_doc(root):
    path = os.path.join(root, "tools", "gen_params_doc.py")
    spec = importlib.util.spec_from_file_location("_gyro_gen_params_doc", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@functools.lru_cache(maxsize=4)
def load_table(root: str = ROOT) -> dict:
    """{id: ParamDef} of the parameter table in the source tree at root."""
    try:
        rows = _gen_params_doc(root).rows(root)
    except Exception as e:  # the generator's GenError, a missing file
        raise ParamSetError(f"cannot read the parameter table under {root}: {e}") from None
    table = {}
    for r in rows:
        pid = int(r["id"], 16)
        table[pid] = ParamDef(pid, r["name"], r["type"], frozenset(r["flags"]),
                              float(r["min"]), float(r["max"]), float(r["default"]),
                              tuple(int(c) for c in r["choices"]), r["unit"])
    return table


@functools.lru_cache(maxsize=4)
def layout_version(root: str = ROOT) -> int:
    """PARAM_LAYOUT_VERSION of the source tree's parameter list."""
    with open(os.path.join(root, "firmware", "params", "param_list.h"), encoding="utf-8") as f:
        m = re.search(r"#define\s+PARAM_LAYOUT_VERSION\s+(\d+)u?", f.read())
    if not m:
        raise ParamSetError("PARAM_LAYOUT_VERSION not found in firmware/params/param_list.h")
    return int(m.group(1))


def by_name(table: dict) -> dict:
    return {d.name: d for d in table.values()}


# ---- float32 ----

def f32(x: float) -> float:
    """x rounded to float32 (ValueError if it rounds to infinity)."""
    if not math.isfinite(x) or abs(x) >= F32_LIMIT:
        raise ValueError(f"{x!r} is not a finite float32")
    return struct.unpack("<f", struct.pack("<f", x))[0]


def f32_bits(x: float) -> int:
    return struct.unpack("<I", struct.pack("<f", f32(x)))[0]


def format_f32(x: float) -> str:
    """The shortest decimal that reads back as exactly f32(x) (9 digits at most), looking
    like a float: positional below 1e16 ("30.0"), with an exponent below 1e-4 and from
    1e16 (the firmware writer's text, host_sim/paramset/param_set.c)."""
    v = f32(x)
    for p in range(1, 10):
        s = "%.*e" % (p - 1, v)
        back = float(s)
        if abs(back) < F32_LIMIT and f32(back) == v and math.copysign(1.0, back) == math.copysign(1.0, v):
            break
    e = int(s.split("e")[1])
    s = "%.*g" % (e + 1 if p <= e < 16 else p, v)
    return s if ("." in s or "e" in s) else s + ".0"


def format_value(d: ParamDef, value) -> str:
    """The value as the firmware's command line and a parameter set write it."""
    return format_f32(value) if d.type == "F32" else str(int(value))


# ---- checks ----

def _bits(d: ParamDef, value) -> int:
    return f32_bits(value) if d.type == "F32" else int(value)


def _range_text(d: ParamDef) -> str:
    if d.type == "ENUM":
        return "one of " + ", ".join(str(c) for c in d.choices)
    lo, hi = (f"{d.min:g}", f"{d.max:g}") if d.type == "F32" else (f"{d.min:.0f}", f"{d.max:.0f}")
    return f"[{lo}, {hi}] {d.unit}"


def check_value(d: ParamDef, value, where: str):
    """The value as the firmware holds it (float32 as a float, or int), or ParamSetError."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParamSetError(f"{where}: value: expected a number")
    if isinstance(value, float) and not math.isfinite(value):
        raise ParamSetError(f"{where}: value: not a finite number")
    rng = _range_text(d)
    if d.type == "F32":
        if abs(value) >= F32_LIMIT:
            raise ParamSetError(f"{where}: value {value:g} is out of range {rng}")
        v = f32(float(value))
        if (v != 0.0 and abs(v) < F32_MIN_NORMAL) or not f32(d.min) <= v <= f32(d.max):
            raise ParamSetError(f"{where}: value {v:.9g} is out of range: {rng}")
        return v
    if value != math.floor(value):
        raise ParamSetError(f"{where}: value {value!r} is not an integer")
    v = int(value)
    if v < 0 or v > 0xFFFFFFFF:
        raise ParamSetError(f"{where}: value {v} is out of range {rng}")
    if d.type == "ENUM" and v not in d.choices:
        raise ParamSetError(f"{where}: value {v} is not an allowed choice: {rng}")
    if d.type == "U32" and not (d.min <= v <= d.max):
        raise ParamSetError(f"{where}: value {v} is out of range: {rng}")
    return v


def _check_keys(obj: dict, where: str, keys, n_required: int):
    for k in getattr(obj, "dups", ()):
        raise ParamSetError(f'{where}: key "{k}" given twice')
    for k in obj:
        if k not in keys:
            raise ParamSetError(f'{where}: unknown key "{k}"')
    for k in keys[:n_required]:
        if k not in obj:
            raise ParamSetError(f'{where}: "{k}" missing')


def _entry(e, k: int, table: dict, seen: set) -> Entry:
    where = f"params[{k}]"
    if not isinstance(e, dict):
        raise ParamSetError(f"{where}: expected an object {{id, name, value}}")
    _check_keys(e, where, ENTRY_KEYS, 3)
    pid = e["id"]
    if not isinstance(pid, str) or not ID_RE.fullmatch(pid):
        raise ParamSetError(f'{where}: id: expected a 16-bit id as a string "0x%04x"')
    pid = int(pid, 16)
    d = table.get(pid)
    if d is None:
        raise ParamSetError(f"{where}: unknown id 0x{pid:04x} in this firmware")
    where = f"params[{k}] (id 0x{pid:04x}, {d.name})"
    if not isinstance(e["name"], str):
        raise ParamSetError(f"{where}: name: expected a string")
    if e["name"] != d.name:
        raise ParamSetError(f'{where}: name "{e["name"]}" does not match the id\'s name in this firmware')
    if "read-only" in d.flags:
        raise ParamSetError(f"{where}: read-only: not a value of a parameter set")
    if "persist" not in d.flags:
        raise ParamSetError(f"{where}: not persistent (flash does not hold it)")
    if pid in seen:
        raise ParamSetError(f"{where}: the id appears more than once")
    seen.add(pid)
    return Entry(pid, d.name, check_value(d, e["value"], where))


def crc32_of(entries, table: dict) -> int:
    """The format's checksum of the entries (in their order)."""
    text = "".join("%04x %08x\n" % (e.id, _bits(table[e.id], e.value)) for e in entries)
    return zlib.crc32(text.encode("ascii")) & 0xFFFFFFFF


class _Obj(dict):
    """A JSON object that remembers the keys given twice (refused where the format has
    keys: at the top level and in an entry; meta is free-form)."""
    dups: tuple = ()


def _pairs(pairs):
    out = _Obj()
    dups = [k for i, (k, _) in enumerate(pairs) if any(k == k2 for k2, _ in pairs[:i])]
    out.update(pairs)
    out.dups = tuple(dups)
    return out


def _no_constant(name):
    raise ParamSetError(f"not valid JSON near '{name}'")


def _header(root: dict) -> tuple:
    if root.get("format") != FORMAT:
        raise ParamSetError(f'format: expected "{FORMAT}" (not a parameter set)')
    fv = root.get("format_version")
    if isinstance(fv, bool) or not isinstance(fv, (int, float)) or fv != FORMAT_VERSION:
        if isinstance(fv, (int, float)) and not isinstance(fv, bool) and fv > FORMAT_VERSION:
            raise ParamSetError(f"format_version {fv:g} is newer than this reader's ({FORMAT_VERSION})")
        raise ParamSetError(f"format_version: expected {FORMAT_VERSION}")
    lv = root.get("layout_version")
    if lv is not None and (isinstance(lv, bool) or not isinstance(lv, (int, float)) or lv != math.floor(lv)
                           or not 0 <= lv <= 65535):
        raise ParamSetError("layout_version: expected an integer in [0, 65535]")
    fw = root.get("firmware")
    if fw is not None and not isinstance(fw, str):
        raise ParamSetError("firmware: expected a string")
    meta = root.get("meta", {})
    if not isinstance(meta, dict):
        raise ParamSetError("meta: expected an object")
    return (None if lv is None else int(lv)), fw, meta


def parse(text: str, table: dict | None = None) -> ParamSet:
    """A parameter set from its JSON text, every check of the format made."""
    table = load_table() if table is None else table
    try:
        root = json.loads(text, object_pairs_hook=_pairs, parse_constant=_no_constant)
    except json.JSONDecodeError as e:
        raise ParamSetError(f"not valid JSON: {e}") from None
    if not isinstance(root, dict):
        raise ParamSetError("top level: expected an object")
    _check_keys(root, "top level", TOP_KEYS, TOP_REQUIRED)
    lv, fw, meta = _header(root)
    if not isinstance(root["params"], list):
        raise ParamSetError("params: expected a list of entries")
    seen: set = set()
    entries = [_entry(e, k, table, seen) for k, e in enumerate(root["params"])]
    crc = root["crc32"]
    if not isinstance(crc, str) or not CRC_RE.fullmatch(crc):
        raise ParamSetError('crc32: expected a string "0x%08x"')
    want, got = int(crc, 16), crc32_of(entries, table)
    if want != got:
        raise ParamSetError(f"checksum mismatch: file edited by hand? crc32 says 0x{want:08x}, the values "
                            f"give 0x{got:08x} (write sets with gyro-sim --save-params or "
                            "tools/gyrotools/paramset.py)")
    return ParamSet(entries, lv, fw, meta)


def read(path, table: dict | None = None) -> ParamSet:
    """parse() of a file; the message starts with its path."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except (OSError, UnicodeDecodeError) as e:
        raise ParamSetError(f"{path}: {e}") from None
    try:
        return parse(text, table)
    except ParamSetError as e:
        raise ParamSetError(f"{path}: {e}") from None


# ---- writing ----

def from_values(values, table: dict | None = None, meta: dict | None = None,
                firmware: str | None = None) -> ParamSet:
    """A checked set of {name: value} (or (name, value) pairs), in the order given."""
    table = load_table() if table is None else table
    names = by_name(table)
    pairs = values.items() if isinstance(values, dict) else values
    entries, seen = [], set()
    for k, (name, value) in enumerate(pairs):
        d = names.get(name)
        if d is None:
            raise ParamSetError(f"{name}: no such parameter")
        raw = {"id": f"0x{d.id:04x}", "name": name, "value": value}
        entries.append(_entry(raw, k, table, seen))
    return ParamSet(entries, layout_version(), firmware, dict(meta or {}))


def dumps(ps: ParamSet, table: dict | None = None) -> str:
    """The file's text (the layout gyro-sim writes), with its checksum."""
    table = load_table() if table is None else table
    seen: set = set()
    entries = [_entry({"id": f"0x{e.id:04x}", "name": e.name, "value": e.value}, k, table, seen)
               for k, e in enumerate(ps.entries)]
    for e in entries:
        if e.value == 0:
            e.value = type(e.value)(0)  # -0 is 0 (the firmware stores +0)
    lines = ["{", f'  "format": "{FORMAT}",', f'  "format_version": {FORMAT_VERSION},']
    if ps.layout_version is not None:
        lines.append(f'  "layout_version": {int(ps.layout_version)},')
    if ps.firmware is not None:
        lines.append(f'  "firmware": {json.dumps(ps.firmware)},')
    if ps.meta:
        lines.append(f'  "meta": {json.dumps(ps.meta, separators=(",", ":"))},')
    rows = [f'\n    {{"id": "0x{e.id:04x}", "name": {json.dumps(e.name)}, '
            f'"value": {format_value(table[e.id], e.value)}}}' for e in entries]
    lines.append('  "params": [' + ",".join(rows) + "\n  ],")
    lines.append(f'  "crc32": "0x{crc32_of(entries, table):08x}"')
    return "\n".join(lines) + "\n}\n"


def write(path, ps: ParamSet, table: dict | None = None) -> None:
    """dumps() into a file (written beside it, then renamed over it)."""
    text = dumps(ps, table)
    tmp = f"{path}.tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)
