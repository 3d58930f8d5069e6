#!/usr/bin/env python3
"""Generate docs/fields.md, the field dictionary, from the tables that define the fields:

    firmware/app/app_tlm_fields.h   telemetry fields (name, type, unit)
    firmware/gyro/gyro_state.h      what each output means (gyro_out_t comments), flag bits
    firmware/gyro/supervisor.h      mode codes and fault bits
    host_sim/gyro_sim/sim_out.c     gyro-sim's CSV header
    tools/gyrotools/fields.py       CSV units (by the name's suffix) and meanings

    gen_fields_doc.py [--root DIR] [--check]
--check compares with the committed docs/fields.md instead of writing it: exit 1 (with a
diff) when it is stale, so a changed table cannot leave the dictionary behind. A field or
column that the descriptions below or fields.CSV_MEANING do not explain is an error
(exit 2), so a new one gets its line.
"""

import argparse
import difflib
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from gyrotools import fields  # noqa: E402

# Meanings of the flag and fault bits whose C definition carries no comment.
BIT_MEANING = {
    "GYRO_FLAG_LOCKED": "drive amplitude and phase within the lock tolerances (mode LOCKED)",
    "GYRO_FLAG_ADC_RAIL": "a drive or sense ADC sample sat at a rail code since the last snapshot",
    "GYRO_FLAG_DRIVE_LIMIT": "the drive command sat at its voltage limit since the last snapshot",
    "GYRO_FLAG_FAULT": "the supervisor holds a fault (mode FAULT)",
    "GYRO_FAULT_ADC_CLIP": "sup.clip_count drive-channel ADC rail codes within 2 ms",
    "GYRO_FAULT_NAN": "a non-finite value in the loop state (checked first)",
    "GYRO_FAULT_LOST_LOCK": "while LOCKED, the low-passed amplitude error stayed beyond the "
                            "lost-lock tolerance for its hold time",
    "GYRO_FAULT_DRIVE_SAT": "while LOCKED, the drive stayed at its voltage limit for its hold "
                            "time; or ACQUIRE at the limit when the acquisition time ran out",
    "GYRO_FAULT_OVER_AMP": "drive amplitude above the relative trip or the absolute level the "
                           "ADC can measure (not checked in SWEEP)",
    "GYRO_FAULT_PHASE_LOST": "while LOCKED, the low-passed phase error stayed beyond "
                             "sup.lost_phase_tol_deg for its hold time",
    "GYRO_FAULT_ACQ_TIMEOUT": "ACQUIRE took longer than the loops' design allows",
    "GYRO_FAULT_LOST_SAMPLE": "the HAL counted a lost sample (a converter frame overrun)",
    "GYRO_FAULT_FREQ_WINDOW": "the tracking drive stayed at the edge of its frequency window (+-0.5 % of f0)",
}
# Telemetry fields whose gyro_out_t comment names a type rather than saying what it is.
TLM_MEANING = {
    "mode": "supervisor mode code (below)",
    "fault": "fault bits of the last fault (below)",
    "flags": "GYRO_FLAG_* bits since the last snapshot (below)",
    "tick": "sample-clock tick count of the snapshot",
}
MODE_MEANING = {
    "OFF": "drive off, no excitation",
    "SWEEP": "self-calibration sweep of the drive resonance (open loop)",
    "ACQUIRE": "drive loops closing, amplitude and phase not yet within tolerance",
    "LOCKED": "drive locked; the rate output is valid when flag RATE_VALID says so",
    "FAULT": "a fault stopped the drive; `status` names it",
}


class GenError(Exception):
    pass


def read(root, rel):
    try:
        with open(os.path.join(root, rel), encoding="utf-8") as fh:
            return fh.read()
    except OSError as e:
        raise GenError(f"{rel}: {e.strerror}") from None


def telemetry(root):
    rows = re.findall(r'X\((\w+),\s*(F32|U32),\s*"([^"]*)"\)', read(root, "firmware/app/app_tlm_fields.h"))
    if not rows:
        raise GenError("firmware/app/app_tlm_fields.h: no X(member, TYPE, unit) rows found")
    return rows


def out_comments(root):
    """Member -> comment of gyro_out_t (a comment covers every name on its line)."""
    src = read(root, "firmware/gyro/gyro_state.h")
    m = re.search(r"typedef struct \{(.*?)\}\s*gyro_out_t;", src, re.S)
    if not m:
        raise GenError("firmware/gyro/gyro_state.h: gyro_out_t not found")
    out = {}
    for _decl, names, comment in re.findall(r"(float|uint32_t)\s+([\w\s,]+);\s*(?:/\*(.*?)\*/)?", m.group(1)):
        for n in names.split(","):
            out[n.strip()] = " ".join((comment or "").split())
    return src, out


def bits(src, pattern, rel):
    rows = re.findall(pattern, src)
    if not rows:
        raise GenError(f"{rel}: no definitions matching {pattern!r}")
    return rows


def csv_columns(root):
    src = read(root, "host_sim/gyro_sim/sim_out.c")
    m = re.search(r'fputs\(((?:\s*"[^"]*")+)', src)
    if not m:
        raise GenError("host_sim/gyro_sim/sim_out.c: the CSV header (fputs of string literals) not found")
    text = "".join(re.findall(r'"([^"]*)"', m.group(1)))
    return [c for c in text.replace("\\n", "").split(",") if c]


def _need(table, key, where):
    if key not in table or not table[key]:
        raise GenError(f"{key}: no description ({where}); add one")
    return table[key]


def generate(root):
    tlm = telemetry(root)
    gyro_h, meaning = out_comments(root)
    sup_h = read(root, "firmware/gyro/supervisor.h")
    flags = bits(gyro_h, r"#define (GYRO_FLAG_\w+) \(1u << (\d+)\)(?:\s*/\*(.*?)\*/)?", "gyro_state.h")
    modes = bits(sup_h, r"GYRO_MODE_(\w+) = (\d+)", "supervisor.h")
    faults = bits(sup_h, r"(GYRO_FAULT_\w+) = 1u << (\d+)", "supervisor.h")
    cols = csv_columns(root)
    L = ["# Field dictionary", "",
         "<!-- Generated by tools/gen_fields_doc.py from firmware/app/app_tlm_fields.h, "
         "firmware/gyro/gyro_state.h, firmware/gyro/supervisor.h, host_sim/gyro_sim/sim_out.c and "
         "tools/gyrotools/fields.py. Do not edit: run `python3 tools/gen_fields_doc.py`; "
         "the test fields_doc_current fails when this file is stale. -->", "",
         "## Telemetry fields (`gyroctl fields`, `gyroctl log`, the `stream` command)", "",
         "Each record holds the selected fields in this order, whatever order they were asked in.",
         "", "| field | type | unit | meaning |", "| --- | --- | --- | --- |"]
    for name, typ, unit in tlm:
        what = TLM_MEANING.get(name) or _need(meaning, name, "a comment in gyro_out_t")
        L.append(f"| `{name}` | {typ.lower()} | {unit} | {what} |")
    L += ["", "## gyro-sim CSV columns (`gyro-sim --csv`)", "",
          "`drive_amp` is the telemetry field `drive_amp_v` under its older name; every "
          "analysis tool accepts either name. (truth): the plant's state, which a board "
          "cannot log.", "", "| column | unit | meaning |", "| --- | --- | --- |"]
    for c in cols:
        u = fields.unit_of(c) or "?"
        L.append(f"| `{c}` | {u} | {_need(fields.CSV_MEANING, c, 'tools/gyrotools/fields.py CSV_MEANING')} |")
    L += ["", "## Flag bits (`flags`)", "", "| bit | value | name | meaning |", "| --- | --- | --- | --- |"]
    for name, bit, comment in flags:
        what = " ".join((comment or "").split()) or _need(BIT_MEANING, name, "BIT_MEANING")
        L.append(f"| {bit} | {1 << int(bit)} | `{name}` | {what} |")
    L += ["", "## Mode codes (`mode`)", "", "| code | name | meaning |", "| --- | --- | --- |"]
    for name, code in modes:
        L.append(f"| {code} | `{name}` | {_need(MODE_MEANING, name, 'MODE_MEANING')} |")
    L += ["", "## Fault bits (`fault`, `status`)", "", "| bit | value | name | meaning |",
          "| --- | --- | --- | --- |"]
    for name, bit in faults:
        L.append(f"| {bit} | {1 << int(bit)} | `{name}` | {_need(BIT_MEANING, name, 'BIT_MEANING')} |")
    return "\n".join(L) + "\n"


def emit(root, rel, text, check, prog):
    """Write text to root/rel or, with check, compare: 0 when current, 1 (with a diff and
    the command that regenerates it) when stale."""
    path = os.path.join(root, rel)
    if check:
        try:
            with open(path, encoding="utf-8") as fh:
                old = fh.read()
        except OSError:
            old = ""
        if old != text:
            sys.stdout.writelines(difflib.unified_diff(old.splitlines(True), text.splitlines(True),
                                                       f"{rel} (committed)", "generated"))
            print(f"{prog}: {rel} is stale: run python3 tools/{prog}.py", file=sys.stderr)
            return 1
        return 0
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(text)
    print(f"wrote {path}")
    return 0


def run(argv, rel, generate_fn, prog):
    """The command line both generators share: write ROOT/rel from generate_fn(root), or
    with --check say whether it is current (exit codes of emit; 2 for a table it cannot
    read)."""
    ap = argparse.ArgumentParser(description=f"Generate {rel}.")
    ap.add_argument("--root", default=os.path.dirname(HERE))
    ap.add_argument("--check", action="store_true", help=f"exit 1 if {rel} is stale")
    a = ap.parse_args(argv)
    try:
        text = generate_fn(a.root)
    except GenError as e:
        print(f"{prog}: {e}", file=sys.stderr)
        return 2
    return emit(a.root, rel, text, a.check, prog)


def main(argv=None):
    return run(argv, "docs/fields.md", generate, "gen_fields_doc")


if __name__ == "__main__":
    sys.exit(main())
