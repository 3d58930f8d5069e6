"""`gyroctl load-params FILE`: a firmware parameter set (docs/param-set.md) into the gyro's
flash, as if the board had been saved with it.

The file is checked first (tools/gyrotools/paramset.py: format, ids, names, kinds,
ranges, checksum); a bad file sends nothing. Then, on the board:

    status                     was the drive running? (mode other than OFF)
    drive off                  non-live parameters and `save` need the drive off
    defaults                   what the set does not list takes its default, as a set
                               loaded from flash does (not with --merge: the board's
                               current values stay)
    set NAME VALUE [...]       the entries in file order, as many pairs per line as fit
                               (each line all or nothing); floats as the shortest text
                               that reads back as the same float32; the gyro's echo of
                               each value is compared with the file's
    save                       into flash
    drive on                   if the drive was running before

Any refused command stops the sequence: the error names the command and the gyro's
answer. The board may then hold part of the set in RAM, unsaved, with the drive off;
`gyroctl load` puts the values stored in flash back (`drive on` restarts the drive).
"""

from __future__ import annotations

import time

from gyrotools import paramset

from .link import LINE_MAX

PENDING_RETRIES = 20  # the sample loop has not yet taken the previous change: retry


class LoadError(Exception):
    """The gyro refused a command of the sequence (the message says which and why)."""


def set_lines(ps: paramset.ParamSet, table: dict) -> list:
    """The `set` lines of the entries, in file order, each at most LINE_MAX bytes."""
    lines, cur = [], "set"
    for e in ps.entries:
        pair = f" {e.name} {paramset.format_value(table[e.id], e.value)}"
        if cur != "set" and len(cur) + len(pair) > LINE_MAX:
            lines.append(cur)
            cur = "set"
        cur += pair
    if cur != "set":
        lines.append(cur)
    return lines


def _send(link, line: str, progress):
    """One command; a refusal raises LoadError naming it (PENDING is retried)."""
    for _ in range(PENDING_RETRIES):
        r = link.command(line)
        if r.ok or r.code != "PENDING":
            break
        time.sleep(0.01)
    if progress:
        progress(f"{line} -> {r.final}")
    if not r.ok:
        raise LoadError(f"`{line}` refused: {r.final}")
    return r


def _check_echo(reply, ps: paramset.ParamSet, table: dict, line: str):
    """The values the gyro took (its `set` echo: NAME VALUE ...) against the file's."""
    words = reply.text.split(" ")
    want = {e.name: (table[e.id], e.value) for e in ps.entries}
    for name, text in zip(words[0::2], words[1::2]):
        if name not in want:
            continue
        d, value = want[name]
        try:
            got = paramset.f32(float(text)) if d.type == "F32" else int(text)
        except ValueError:
            got = None
        if got != value:
            raise LoadError(f"`{line}`: the gyro holds {name} {text}, the file says "
                            f"{paramset.format_value(d, value)}")


def load(link, ps: paramset.ParamSet, table: dict | None = None, merge: bool = False,
         progress=None) -> dict:
    """Run the sequence on a synced link. Returns {"was_running", "lines", "saved"}; raises
    LoadError on the first refusal."""
    table = paramset.load_table() if table is None else table
    st = link.command("status")
    if not st.ok:
        raise LoadError(f"`status` refused: {st.final}")
    mode = st.text.split(" ")[0]
    was_running = mode != "OFF"
    _send(link, "drive off", progress)
    if not merge:
        _send(link, "defaults", progress)
    lines = set_lines(ps, table)
    for line in lines:
        _check_echo(_send(link, line, progress), ps, table, line)
    saved = _send(link, "save", progress).text
    if was_running:
        _send(link, "drive on", progress)
    return {"was_running": was_running, "lines": len(lines), "saved": saved, "mode": mode}

