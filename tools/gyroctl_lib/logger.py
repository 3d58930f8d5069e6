"""`gyroctl log`: start a telemetry stream, decode its frames, write a CSV log.

CSV (the format tools/gyrotools/csvlog.py reads): '#' comment lines with the stream's
description, one header row `t_s,<columns>`, one row per record, and '#' comment lines
with the loss accounting at the end. t_s is the stream's own clock, record index *
decim / fs_hz from the stream's first record, so rows are exactly 1/rate apart and a
lost record shows as a gap. Columns carry the names the user asked for (drive_amp_v
stays drive_amp_v; gyro-sim's name drive_amp is accepted too and kept as typed), and the
analysis tools read either (tools/gyrotools/csvlog.py); integers (flags, mode, fault,
tick) are decimal, as in gyro-sim's logs.

--duration is gyro time, not wall time: the file holds the records with index
0 .. round(duration * rate) - 1, however fast the link or the gyro runs. On the emulator
the gyro runs `stretch` times slower than real time (`emu`), so the wait for each record
is scaled by it: the log gives up only when no record has come for --timeout seconds
plus four frame periods of wall time (a frame carries `per_frame` records, as the
stream's reply says; four, because a loaded host slows the emulator below its stretch).
"""

from __future__ import annotations

import dataclasses
import datetime
import sys
import time

from . import frames
from .link import CommandError, LinkError

# firmware field name -> column name of the analysis tools' logs
COLUMN_NAMES = {"drive_amp_v": "drive_amp"}
FIELD_NAMES = {v: k for k, v in COLUMN_NAMES.items()}


def column_name(field: str) -> str:
    return COLUMN_NAMES.get(field, field)


def field_name(arg: str) -> str:
    """Accept a firmware field name or its log column name."""
    return FIELD_NAMES.get(arg, arg)


def format_value(name: str, ftype: int, v) -> str:
    if ftype == frames.T_F32:
        return "%.9g" % v  # nine significant digits round-trip a float32
    return "%d" % v


@dataclasses.dataclass
class LogResult:
    path: str
    stream_id: int = 0
    rate_hz: float = 0.0
    wanted: int = 0          # records in [0, duration)
    rows: int = 0            # written
    missing: int = 0         # wanted - rows: lost at the source or on the link
    lost_at_source: int = 0  # ring overruns in the firmware (stop reply)
    frames_missing: int = 0  # frames of the stream that never decoded
    corrupt: int = 0         # damaged frames seen
    stop_reply: str = ""

    def summary(self) -> str:
        return (f"{self.rows} records ({self.rows / self.rate_hz if self.rate_hz else 0:.3f} s at "
                f"{self.rate_hz:g} Hz) to {self.path}; missing records {self.missing}, "
                f"frames missing {self.frames_missing}, corrupt frames {self.corrupt}, "
                f"lost at source {self.lost_at_source}")

    @property
    def clean(self) -> bool:
        return self.missing == 0 and self.frames_missing == 0 and self.corrupt == 0


class LogError(Exception):
    pass


def _progress_bar(done, total, width=40):
    frac = 0.0 if total == 0 else min(1.0, done / total)
    n = int(frac * width)
    sys.stderr.write("\r[" + "#" * n + "." * (width - n) + f"] {100 * frac:5.1f}% {done}/{total}")
    sys.stderr.flush()


class _ProgressLines:
    """Progress for a log or a pipe: one line at each quarter, so a long recording
    is not silent and the output stays readable."""

    def __init__(self, stream):
        self.stream, self.next_q = stream, 1

    def __call__(self, done, total):
        while total and self.next_q <= 4 and done * 4 >= total * self.next_q:
            self.stream.write(f"gyroctl: log: {25 * self.next_q}% ({done} of {total} records)\n")
            self.stream.flush()
            self.next_q += 1


def emu_stretch(link) -> int:
    """The emulator's tick stretch (gyro time runs this many times slower than real
    time); 1 on a board or the simulator, which have no `emu` command."""
    r = link.command("emu")
    if not r.ok:
        return 1
    for d in r.data:
        w = d.split()
        if len(w) == 2 and w[0] == "stretch":
            try:
                return max(1, int(w[1]))
            except ValueError:
                return 1
    return 1


def log(link, fields, rate_hz, duration_s, out_path, progress=None, timeout_s=None) -> LogResult:
    """Stream `fields` at rate_hz (None: the gyro's tlm.rate_hz) for duration_s seconds of
    stream time into out_path. progress(done, total) is called as rows come in."""
    if not duration_s > 0:
        raise LogError("--duration must be > 0")
    names = [field_name(f) for f in fields]
    asked = {field_name(f): f for f in fields}  # header: the names as the user typed them
    stretch = emu_stretch(link)
    stall_s = (3.0 if timeout_s is None else timeout_s)
    res = LogResult(path=str(out_path))
    st = {"layout": None, "max_index": -1, "rows": 0, "wanted": None, "fh": None}
    stats0 = dataclasses.replace(link.decoder.stats)

    pending = []  # frames decoded in the same read as the `stream` reply, before its id is known

    def on_header(lay):
        if res.stream_id == 0:
            pending.append((on_header, lay))
            return
        if lay.stream_id != res.stream_id:
            return
        if st["layout"] is None:
            st["layout"] = lay
            st["wanted"] = max(1, round(duration_s * lay.rate_hz))
            fh = st["fh"]
            fh.write(f"# gyroctl log: stream {lay.stream_id} from {link.port}, started "
                     f"{datetime.datetime.now().isoformat(timespec='seconds')}\n")
            fh.write(f"# fs_hz {lay.fs_hz}, decim {lay.decim}, rate_hz {lay.rate_hz:.9g}, "
                     f"fields {' '.join(lay.names)}\n")
            fh.write(",".join(["t_s"] + [asked.get(n, n) for n in lay.names]) + "\n")

    def on_data(fr):
        if res.stream_id == 0:
            pending.append((on_data, fr))
            return
        lay = st["layout"]
        if lay is None or fr.layout.stream_id != lay.stream_id:
            return
        fh = st["fh"]
        for r, values in enumerate(fr.records):
            idx = fr.first_rec + r
            st["max_index"] = max(st["max_index"], idx)
            if idx >= st["wanted"]:
                continue
            cells = [repr(lay.time_s(idx))]
            cells += [format_value(n, t, v) for (n, t), v in zip(lay.fields, values)]
            fh.write(",".join(cells) + "\n")
            st["rows"] += 1
        if progress:
            progress(min(st["rows"], st["wanted"]), st["wanted"])

    try:
        fh = open(out_path, "w", encoding="ascii", newline="\n")
    except OSError as e:
        raise LogError(f"cannot write {out_path}: {e.strerror}") from None
    st["fh"] = fh
    link.on_header, link.on_data = on_header, on_data
    try:
        cmd = "stream " + " ".join(names) + ("" if rate_hz is None else f" @{rate_hz:.9g}")
        r = link.command(cmd)
        if not r.ok:
            raise CommandError(r)
        words = r.text.split(" ")
        try:
            res.stream_id = int(words[1])
            res.rate_hz = float(words[2])
        except (IndexError, ValueError):
            raise LogError(f"unexpected reply to {cmd}: {r.final}") from None
        for handler, item in pending:
            handler(item)
        pending.clear()
        # Give up only on silence: --timeout plus four frame periods of wall time (the
        # emulator's gyro time runs `stretch` times slower).
        per_frame = 1
        if "per_frame" in words[:-1]:
            try:
                per_frame = max(1, int(words[words.index("per_frame") + 1]))
            except ValueError:
                per_frame = 1
        stall_s += 4.0 * per_frame * stretch / max(res.rate_hz, 1e-3)
        last, seen = time.monotonic(), -2
        while st["wanted"] is None or st["max_index"] < st["wanted"] - 1:
            if st["max_index"] != seen:
                last, seen = time.monotonic(), st["max_index"]
            elif time.monotonic() - last > stall_s:
                break
            link.poll()
        stop = link.command("stop")
        res.stop_reply = stop.final
        timed_out = st["wanted"] is None or st["max_index"] < st["wanted"] - 1
    finally:
        link.on_header = link.on_data = None
        if progress is _progress_bar and st["wanted"]:
            sys.stderr.write("\n")
    s = link.decoder.stats
    res.wanted = st["wanted"] or 0
    res.rows = st["rows"]
    res.missing = res.wanted - res.rows
    res.frames_missing = s.seq_missing - stats0.seq_missing
    res.corrupt = s.corrupt - stats0.corrupt
    w = res.stop_reply.split(" ")
    if len(w) >= 7 and w[0] == "ok" and w[1] == "stop" and w[5] == "lost":
        res.lost_at_source = int(w[6])
    fh.write(f"# {res.summary()}\n# stop reply: {res.stop_reply}\n")
    fh.close()
    if timed_out:
        raise LogError(f"stream stalled: {res.rows} of {res.wanted or '?'} records arrived, "
                       f"then none for {stall_s:.1f} s (--timeout, emulator stretch "
                       f"{stretch}); partial log in {out_path}")
    return res


def progress_for(stream) -> callable:
    """A progress bar on stream (stderr) if it is a terminal, else a line per quarter."""
    return _progress_bar if stream.isatty() else _ProgressLines(stream)


__all__ = ["log", "LogResult", "LogError", "column_name", "field_name", "progress_for", "LinkError"]
