"""A part on a UART port (tools/calibrate --port): the flow's stages run on a board, or
on a simulated one behind gyro-sim's UART session, through the firmware's command line.

The flow's scenarios (gyro-sim's JSON: "duration_s", the "rate_dps" and "ambient_c"
profiles, "commands", "plant": {"cold_start"}, "csv_rate_hz") are played on the part by
a bench that moves the rate table and the chamber:
- EmuBench: the simulated bench's commands (gyro-sim --uart-pty: `emu rate DPS EDGE_S`,
  `emu ambient DEGC EDGE_S`, `emu cold`), each move timed by the part's own clock (the
  reply's t_s);
- ManualBench: an operator at a real table and chamber, prompted on the terminal; a move
  counts from the moment Enter is pressed (the table or the chamber holds by then).
A run (PortTarget.run): the param set loaded and saved (defaults first, as a part
starts from its flash), the drive stopped, the bench at the profile's start (the chamber
soaked: SOAK_S of gyro time on the simulated bench, the operator's word on a real one; a
cold start: `emu cold`, or a power cycle after a night off), telemetry streamed (FIELDS),
the drive started (t_s = 0 at the first record out of OFF: a simulated run's power-on,
to one record), then the profile played in the stream's time and the scenario's commands
typed when due. The log is written as gyro-sim's CSV (DIR/work/NAME.csv) with the
bench's setpoints as rate_true_dps and t_ambient_c, the truth a bench knows; a board has
no other (no structure temperature), so the analyses read those columns only where
logged. Gyro time is the telemetry's sample tick (unwrapped), so the log is the part's
own clock even when the link lags.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time

import numpy as np

from . import csvlog, paramset
from .errors import InputError

FIELDS = ("rate_dps", "rate_unc_dps", "quad_dps", "drive_amp_v", "p_deg", "p_f_deg",
          "mode", "flags", "tick", "rate_valid", "f_drive_hz", "rate_invalid")
MAX_RATE_HZ = 200.0       # the stream's rate: 12 fields at 200 Hz is 11 % of the link
SOAK_S = 1800.0           # a chamber change before a run: 4.5 of the default part's 400 s
SOAK_MIN_K = 0.5          # a smaller change is no soak
HEAT_COOL_STEP_S = 5.0    # an exponential chamber program as linear moves of this length
MODE_OFF = 0


class PortError(InputError):
    """The part or the bench refused or went away: the message says which and why."""


@dataclasses.dataclass
class Move:
    t_s: float       # scenario time it starts
    which: str       # "rate" (deg/s) or "ambient" (degC)
    to: float
    edge_s: float


def _steps(prof, which, default_edge_s):
    steps = prof["steps"]
    edge = float(prof.get("edge_s", default_edge_s))
    moves, t = [], 0.0
    for (dur, _), (_, v) in zip(steps[:-1], steps[1:]):
        t += float(dur)
        moves.append(Move(t, which, float(v), max(edge, 1e-3)))
    return float(steps[0][1]), moves


def _heat_cool(prof, which):
    """The heat gun and the room as linear moves of HEAT_COOL_STEP_S towards the curve."""
    base, hot = float(prof["value"]), float(prof["hot_value"])
    t0, heat = float(prof["t_start_s"]), float(prof["heat_s"])
    tau_h, tau_c = float(prof["tau_heat_s"]), float(prof["tau_cool_s"])
    peak = base + (hot - base) * (1.0 - math.exp(-heat / tau_h))

    def at(t):
        if t <= t0:
            return base
        if t <= t0 + heat:
            return base + (hot - base) * (1.0 - math.exp(-(t - t0) / tau_h))
        return base + (peak - base) * math.exp(-(t - t0 - heat) / tau_c)

    end = t0 + heat + 8.0 * tau_c  # within 0.03 % of the base after
    ts = np.arange(t0, end, HEAT_COOL_STEP_S)
    return base, [Move(float(t), which, at(t + HEAT_COOL_STEP_S), HEAT_COOL_STEP_S) for t in ts]


def profile_moves(prof, which, default, default_edge_s):
    """(the value at t = 0, the moves that play the profile) of a scenario profile."""
    if prof is None:
        return default, []
    kind = prof.get("kind", "const")
    if kind == "const":
        return float(prof["value"]), []
    if kind == "steps":
        return _steps(prof, which, default_edge_s)
    if kind == "ramp":
        v0, t0, t1 = float(prof["value"]), float(prof["t_start_s"]), float(prof["t_end_s"])
        to = v0 + float(prof["slope_per_s"]) * (t1 - t0)
        return v0, ([Move(t0, which, to, t1 - t0)] if t1 > t0 else [])
    if kind == "heat_cool" and which == "ambient":
        return _heat_cool(prof, which)
    raise PortError(f"{which} profile of kind {kind!r}: a bench plays steps, constants, "
                    "ramps and (the chamber) heat_cool")


@dataclasses.dataclass
class Timeline:
    duration_s: float
    rate0_dps: float
    ambient0_c: float
    moves: list
    commands: list   # [(t_s, line)]
    cold_start: bool
    rate_hz: float


def timeline(scen):
    """The run a scenario (gyro-sim's JSON) asks of a bench."""
    if scen.get("selfcal"):
        raise PortError("a selfcal scenario is run by PortTarget.selfcal")
    r0, rm = profile_moves(scen.get("rate_dps"), "rate", 0.0, 0.1)
    a0, am = profile_moves(scen.get("ambient_c"), "ambient", 25.0, 60.0)
    plant = scen.get("plant") or {}
    unknown = sorted(set(plant) - {"cold_start"})
    if unknown:
        raise PortError(f"plant settings {', '.join(unknown)}: a board's plant is the part "
                        "itself (only cold_start, a power cycle, is played)")
    cmds = sorted((float(t), str(line)) for t, line in scen.get("commands", []))
    return Timeline(float(scen["duration_s"]), r0, a0, sorted(am + rm, key=lambda m: m.t_s),
                    cmds, bool(plant.get("cold_start")),
                    min(float(scen.get("csv_rate_hz", MAX_RATE_HZ)), MAX_RATE_HZ))


class Truth:
    """A bench input's setpoint over gyro time, from the moves as they were played."""

    def __init__(self, value):
        self.segments = [(-math.inf, value, value, 0.0)]  # (start, from, to, edge)

    def now(self, t):
        start, v0, v1, edge = self.segments[-1]
        return v1 if edge <= 0.0 or t >= start + edge else v0 + (v1 - v0) * (t - start) / edge

    def move(self, t, to, edge_s):
        self.segments.append((t, self.now(t), to, edge_s))

    def at(self, ts):
        out = np.empty_like(ts)
        starts = np.array([s[0] for s in self.segments])
        k = np.searchsorted(starts, ts, side="right") - 1
        for i, (start, v0, v1, edge) in enumerate(self.segments):
            m = k == i
            if edge <= 0.0:
                out[m] = v1
            else:
                out[m] = v0 + (v1 - v0) * np.clip((ts[m] - start) / edge, 0.0, 1.0)
        return out


class EmuBench:
    """The simulated bench of gyro-sim's UART session (and the emulated board's table)."""
    name = "emu"

    def __init__(self, link):
        self.link = link

    def _cmd(self, line):
        r = self.link.command(line)
        if not r.ok:
            raise PortError(f"the bench refused `{line}`: {r.final}")
        return r

    def move(self, which, to, edge_s, t_now):
        """Start the move; returns the gyro time it starts at (the reply's t_s)."""
        words = self._cmd(f"emu {which} {to:.9g} {edge_s:.9g}").text.split()
        return float(words[words.index("t_s") + 1]) if "t_s" in words else t_now

    def soak(self, ambient_c, t_now):
        """The chamber to ambient_c; the gyro time to soak there (none when it is there)."""
        r = self._cmd("emu")
        now = dict(d.split(" ", 1) for d in r.data if " " in d)
        self.move("ambient", ambient_c, 1.0, t_now)
        return 0.0 if abs(float(now.get("ambient_c", "nan")) - ambient_c) < SOAK_MIN_K \
            else SOAK_S

    def cold(self, ambient_c, t_now):
        """The chamber to ambient_c and the part as after a night off there."""
        self.move("ambient", ambient_c, 1e-3, t_now)
        self._cmd("emu cold")


class ManualBench:
    """An operator at a real rate table and chamber, prompted on a terminal."""
    name = "manual"

    def __init__(self, ask=input, say=None):
        self.ask = ask
        self.say = say or (lambda s: print(s, file=sys.stderr))

    def _confirm(self, text):
        self.say(f"calibrate: BENCH: {text}")
        self.ask("calibrate: press Enter when done ")

    def move(self, which, to, edge_s, t_now):
        what = (f"turn the rate table to {to:+.6g} deg/s" if which == "rate" else
                f"set the chamber to {to:.6g} degC")
        self._confirm(f"{what} (over {edge_s:.3g} s if the bench can; Enter when it holds)")
        return t_now

    def soak(self, ambient_c, t_now):
        self._confirm(f"set the chamber to {ambient_c:.6g} degC and let the part soak there "
                      "(its structure and board settled)")
        return 0.0

    def cold(self, ambient_c, t_now):
        self._confirm(f"set the chamber to {ambient_c:.6g} degC, switch the part off, let it "
                      "reach the chamber's temperature (hours), then switch it on")


def bench_for(name, link):
    if name == "emu":
        return EmuBench(link)
    if name == "manual":
        return ManualBench()
    raise PortError(f"bench {name!r}: emu or manual")


class _Stream:
    """One telemetry stream of FIELDS: rows as they arrive, gyro time from the tick."""

    def __init__(self, link):
        self.link, self.rows, self.layout, self.sid = link, [], None, None
        self.ticks = 0  # unwrapped tick of the last row
        self._last_raw = None
        self._pending = []

    def _header(self, lay):
        if self.sid is None:
            self._pending.append((self._header, lay))
        elif lay.stream_id == self.sid and self.layout is None:
            self.layout = lay

    def _data(self, fr):
        if self.sid is None:
            self._pending.append((self._data, fr))
            return
        if self.layout is None or fr.layout.stream_id != self.sid:
            return
        k = self.layout.names.index("tick")
        for values in fr.records:
            raw = int(values[k])
            step = 0 if self._last_raw is None else (raw - self._last_raw) & 0xFFFFFFFF
            self._last_raw = raw
            self.ticks += step if self.rows else raw
            self.rows.append((self.ticks,) + tuple(values))

    def start(self, rate_hz):
        self.link.on_header, self.link.on_data = self._header, self._data
        r = self.link.command("stream " + " ".join(FIELDS) + f" @{rate_hz:.9g}")
        if not r.ok:
            raise PortError(f"the part refused the telemetry stream: {r.final}")
        self.sid = int(r.text.split(" ")[1])
        for fn, item in self._pending:
            fn(item)
        self._pending.clear()

    def stop(self):
        self.link.command("stop")
        self.link.on_header = self.link.on_data = None

    def t_now(self, tick0):
        """Gyro time of the last row since tick0 (None before the first row)."""
        if not self.rows or self.layout is None:
            return None
        return (self.ticks - tick0) / self.layout.fs_hz


@dataclasses.dataclass
class PortTarget:
    """The part behind a port: each of the flow's runs played on it by a bench."""
    port: str
    bench: str = "emu"
    timeout_s: float = 10.0
    say: object = None

    def __post_init__(self):
        self.say = self.say or (lambda s: print(s, file=sys.stderr))

    def _link(self):
        from gyroctl_lib.link import Link, LinkError
        try:
            link = Link(self.port, timeout_s=self.timeout_s)
            link.sync()
        except LinkError as e:
            raise PortError(str(e)) from None
        return link

    def describe(self, what):
        return f"gyroctl --port {self.port} (bench {self.bench}): {what}"

    def _load(self, link, params_path):
        from gyroctl_lib import load_params
        try:
            load_params.load(link, paramset.read(params_path))
        except load_params.LoadError as e:
            raise PortError(f"{params_path} on the part: {e}") from None
        self._cmd(link, "drive off")

    @staticmethod
    def _cmd(link, line):
        """One command; PENDING (the sample loop has not yet taken the last change) is
        retried as gyroctl load-params retries it; any other refusal raises."""
        from gyroctl_lib import load_params
        for _ in range(load_params.PENDING_RETRIES):
            r = link.command(line)
            if r.ok or r.code != "PENDING":
                break
            time.sleep(0.01)
        if not r.ok:
            raise PortError(f"the part refused `{line}`: {r.final}")
        return r

    def selfcal(self, out_params, config=None):
        """The firmware's sweep from its generic defaults and the sense configuration
        config (name -> value, calflow.sense_config), its result saved and read back as a
        param set (the persistent values): the figures of `status`."""
        from gyroctl_lib import sweep
        link = self._link()
        try:
            for line in ("drive off", "defaults"):
                self._cmd(link, line)
            if config:
                self._cmd(link, "set " + " ".join(f"{k} {v}" for k, v in config.items()))
            try:
                st = sweep.run_and_wait(link, timeout_s=600.0)
            except sweep.SweepError as e:
                raise PortError(f"self-calibration: {e}") from None
            for line in ("drive off", "save"):  # the firmware saves only a stopped drive
                self._cmd(link, line)
            write_params(link, out_params)
        finally:
            link.close()
        return {k: _num(st.get(k)) for k in ("selfcal_f0_hz", "selfcal_q", "selfcal_s")}

    def run(self, params_path, scen, log_path):
        """Play the scenario on the part from params_path; writes log_path (gyro-sim's
        CSV layout). Returns the replies to the scenario's commands."""
        tl = timeline(scen)
        link = self._link()
        try:
            bench = bench_for(self.bench, link)
            self._load(link, params_path)
            return _play(link, bench, tl, log_path, self.say)
        finally:
            link.close()


def _num(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return None


def write_params(link, path):
    """The part's persistent values (`list`) as a param set at path."""
    table = paramset.load_table()
    defs = paramset.by_name(table)
    values = {}
    for p in _list(link):
        d = defs.get(p[0])
        if d is None or "persist" not in d.flags or "read-only" in d.flags:
            continue
        values[p[0]] = float(p[1]) if d.type == "F32" else int(p[1])
    paramset.write(path, paramset.from_values(values, table))


def _list(link):
    r = link.command("list")
    if not r.ok:
        raise PortError(f"the part refused `list`: {r.final}")
    return [d.split(" ", 2) for d in r.data]


def _poll_until(link, st, done, what, wall_timeout_s=30.0):
    """Poll the link until done() holds; PortError when the stream stalls."""
    import time
    last, seen = time.monotonic(), len(st.rows)
    while not done():
        link.poll()
        if len(st.rows) != seen:
            last, seen = time.monotonic(), len(st.rows)
        elif time.monotonic() - last > wall_timeout_s:
            raise PortError(f"the telemetry stalled while {what} ({len(st.rows)} records)")


def _power_on(link, bench, tl, st, say):
    """The bench at the profile's start, the part soaked (or cold), the drive started:
    the tick of t_s = 0."""
    fs = st.layout.fs_hz
    g = lambda: st.ticks / fs  # noqa: E731  (gyro time of the last record)
    bench.move("rate", tl.rate0_dps, 0.5, g())
    if tl.cold_start:  # a night off at the ambient: no soak powered
        bench.cold(tl.ambient0_c, g())
    else:
        soak = bench.soak(tl.ambient0_c, g())
        t_end = g() + soak
        if soak > 0.0:
            say(f"calibrate: port: soaking {soak:g} s of gyro time at {tl.ambient0_c:g} degC")
        _poll_until(link, st, lambda: g() >= t_end, "soaking")
    n = len(st.rows)
    PortTarget._cmd(link, "drive on")
    k = FIELDS.index("mode") + 1
    _poll_until(link, st, lambda: any(r[k] != MODE_OFF for r in st.rows[n:]), "starting the drive")
    return next(r[0] for r in st.rows[n:] if r[k] != MODE_OFF)


def _play(link, bench, tl, log_path, say):
    st = _Stream(link)
    st.start(tl.rate_hz)
    try:
        _poll_until(link, st, lambda: st.layout is not None and st.rows, "starting the stream")
        fs = st.layout.fs_hz
        tick0 = _power_on(link, bench, tl, st, say)
        rate, amb = Truth(tl.rate0_dps), Truth(tl.ambient0_c)
        events = sorted([(m.t_s, 0, m) for m in tl.moves] + [(t, 1, c) for t, c in tl.commands],
                        key=lambda e: (e[0], e[1]))
        replies = []
        for t_ev, kind, ev in events + [(tl.duration_s, 2, None)]:
            _poll_until(link, st, lambda t=t_ev: st.t_now(tick0) >= t, "playing the profile")
            if kind == 0:
                t_abs = bench.move(ev.which, ev.to, ev.edge_s, st.ticks / fs)
                (rate if ev.which == "rate" else amb).move(t_abs - tick0 / fs, ev.to, ev.edge_s)
            elif kind == 1:
                r = link.command(ev)
                replies.append("".join(f"- {d}\n" for d in r.data) + r.final + "\n")
    finally:
        st.stop()
    _write_log(st, tick0, rate, amb, tl.duration_s, log_path)
    return replies


def _write_log(st, tick0, rate, amb, duration_s, path):
    rows = np.array(st.rows, dtype=float)
    t = (rows[:, 0] - tick0) / st.layout.fs_hz
    keep = (t >= 0.0) & (t <= duration_s)
    rows, t = rows[keep], t[keep]
    names = ["t_s", "rate_true_dps", "t_ambient_c"] + list(st.layout.names)
    cols = [t, rate.at(t), amb.at(t)] + [rows[:, 1 + i] for i in range(len(st.layout.names))]
    with open(path, "w", encoding="ascii", newline="\n") as fh:
        fh.write(",".join(names) + "\n")
        for i in range(t.size):
            fh.write(",".join(repr(float(c[i])) for c in cols) + "\n")


def read(path, columns, want=()):
    return csvlog.read_log(path, need=columns, want=want, purpose=path)
