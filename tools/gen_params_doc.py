#!/usr/bin/env python3
"""Generate docs/parameters.md, the parameter reference, from the parameter table:

    firmware/params/param_list.h    X(sym, id, name, TYPE, unit, min, max, default,
                                      choices, flags, help) rows, each after the comment
                                      that gives the reason for its default

    gen_params_doc.py [--root DIR] [--check]
--check compares with the committed docs/parameters.md instead of writing it: exit 1
(with a diff) when it is stale, so a changed row cannot leave the reference behind. A
row that cannot be read is an error (exit 2).
"""

import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from gen_fields_doc import GenError, read, run  # noqa: E402

SRC = "firmware/params/param_list.h"
# The reference board's facts, which some defaults name (sys.fs_hz: the sample rate).
BOARD = "hal/boards/ref_f405/include/board.h"
FLAG_WORD = {"PF_PERSIST": "persist", "PF_READONLY": "read-only", "PF_LIVE": "live",
             "PF_RESTART": "restart"}
GROUP_TITLE = {
    "drive": "Drive loops (`drive.*`)",
    "demod": "Demodulators (`demod.*`)",
    "rate": "Rate channel (`rate.*`)",
    "sup": "Supervisor (`sup.*`)",
    "selftest": "Self-test (`selftest.*`)",
    "quad": "Quadrature nulling (`quad.*`)",
    "sense": "Sense axis: force rebalance (`sense.*`)",
    "tlm": "Telemetry (`tlm.*`)",
    "sys": "System (`sys.*`)",
}


def split_args(s):
    """The top-level comma-separated arguments of s (strings and parentheses kept whole)."""
    out, depth, cur, q = [], 0, [], False
    for i, ch in enumerate(s):
        if q:
            cur.append(ch)
            if ch == '"' and s[i - 1] != "\\":
                q = False
            continue
        if ch == '"':
            q = True
        elif ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
        elif ch == "," and depth == 0:
            out.append("".join(cur).strip())
            cur = []
            continue
        cur.append(ch)
    out.append("".join(cur).strip())
    return out


def c_string(s):
    m = re.fullmatch(r'"((?:\\.|[^"\\])*)"', s)
    if not m:
        raise GenError(f"{SRC}: expected a string, found {s!r}")
    return m.group(1).replace('\\"', '"')


def board_macros():
    """#define NAME VALUE lines of the reference board's header."""
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", BOARD)
    with open(path, encoding="utf-8") as f:
        return dict(re.findall(r"^#define\s+(BOARD_\w+)\s+(\S+)", f.read(), re.M))


def number(s):
    """A C constant as written in the table, without its type suffix; a board macro by
    its value on the reference board."""
    s = s.strip()
    if re.fullmatch(r"BOARD_\w+", s):
        s = board_macros().get(s, s)
    if re.fullmatch(r"0[xX][0-9a-fA-F]+[uU]?", s):
        return str(int(s.rstrip("uU"), 16))
    m = re.fullmatch(r"(-?[0-9.]+(?:[eE][-+]?[0-9]+)?)[fFuU]?", s)
    if not m:
        raise GenError(f"{SRC}: cannot read the number {s!r}")
    return m.group(1)


def rows(root):
    text = read(root, SRC)
    # the macro runs to the first blank line (a comment line inside it needs no backslash)
    m = re.search(r"#define PARAM_LIST\(X\)[ \t]*\\\n(.*?)\n[ \t]*\n", text, re.S)
    if not m:
        raise GenError(f"{SRC}: #define PARAM_LIST(X) not found")
    body = re.sub(r"\\\n", "\n", m.group(1))
    out, reason = [], []
    pos = 0
    tok = re.compile(r"/\*(.*?)\*/|X\(", re.S)
    while True:
        t = tok.search(body, pos)
        if not t:
            break
        if t.group(0).startswith("/*"):
            lines = [re.sub(r"^\s*\*\s?", "", ln) for ln in t.group(1).split("\n")]
            reason.append(" ".join(" ".join(lines).split()))
            pos = t.end()
            continue
        depth, i = 1, t.end()
        while depth:
            if body[i] == "(":
                depth += 1
            elif body[i] == ")":
                depth -= 1
            elif body[i] == '"':
                i = body.index('"', i + 1)
                while body[i - 1] == "\\":
                    i = body.index('"', i + 1)
            i += 1
        args = split_args(" ".join(body[t.end():i - 1].split()))
        if len(args) != 11:
            raise GenError(f"{SRC}: a row with {len(args)} fields instead of 11: {args[:3]}")
        sym, pid, name, typ, unit, lo, hi, dflt, choices, flags, hlp = args
        out.append({
            "name": c_string(name), "id": f"0x{int(pid.rstrip('uU'), 16):04X}", "type": typ,
            "unit": c_string(unit), "min": number(lo), "max": number(hi), "default": number(dflt),
            "choices": [number(c) for c in re.findall(r"PARAM_CHOICE\(([^)]*)\)", choices)],
            "flags": [FLAG_WORD[f.strip()] for f in flags.split("|") if f.strip() in FLAG_WORD],
            "help": c_string(hlp), "reason": " ".join(reason),
        })
        reason = []
        pos = i
    if not out:
        raise GenError(f"{SRC}: no X(...) rows found")
    return out


def cell(s):
    return s.replace("|", "\\|")


def generate(root):
    ps = rows(root)
    L = ["# Parameter reference", "",
         f"<!-- Generated by tools/gen_params_doc.py from {SRC}. Do not edit: run "
         "`python3 tools/gen_params_doc.py`; the test parameters_doc_current fails when this "
         "file is stale. -->", "",
         "Every firmware parameter, as the command line (`list`, `get`, `set`, `help NAME`) "
         "and `gyro-sim --set firmware.NAME=VALUE` know it. Flags: *persist* saved by `save`; "
         "*live* may change while the drive runs (the others need the drive off); "
         "*read-only* refused by `set`; *restart* read at start-up only. The id is the "
         "record's key in a stored image. The last column is the reason for the default.", ""]
    groups = []
    for p in ps:
        g = p["name"].split(".", 1)[0]
        if g not in groups:
            groups.append(g)
    for g in groups:
        L += [f"## {GROUP_TITLE.get(g, f'`{g}.*`')}", "",
              "| name | unit | default | range | flags | id | meaning | why this default |",
              "| --- | --- | --- | --- | --- | --- | --- | --- |"]
        for p in ps:
            if p["name"].split(".", 1)[0] != g:
                continue
            rng = ", ".join(p["choices"]) if p["type"] == "ENUM" else f"{p['min']} .. {p['max']}"
            if p["type"] == "ENUM":
                rng = "{" + rng + "}"
            unit = "" if p["unit"] == "-" else p["unit"]
            L.append(f"| `{p['name']}` | {cell(unit)} | {p['default']} | {rng} | "
                     f"{', '.join(p['flags'])} | {p['id']} | {cell(p['help'])} | {cell(p['reason'])} |")
        L.append("")
    return "\n".join(L)


def main(argv=None):
    return run(argv, "docs/parameters.md", generate, "gen_params_doc")


if __name__ == "__main__":
    sys.exit(main())
