"""The `gyroctl` command: tune, save and log the gyro over its UART.

    gyroctl --port PORT shell                    interactive command line, tab completion
    gyroctl --port PORT get NAME                 prints the value
    gyroctl --port PORT set NAME VALUE [NAME VALUE ...]   all or nothing, one tick
    gyroctl --port PORT save | load | defaults | diff | status | version | help | stop
    gyroctl --port PORT list [PREFIX]
    gyroctl --port PORT drive on|off
    gyroctl --port PORT fields                   the telemetry fields: name, type, unit
    gyroctl --port PORT sweep-csv [--run] --out FILE.csv   the latest sweep's points (or
                                                 a new sweep's, --run) as the CSV of
                                                 gyro-freqresp
    gyroctl --port PORT log FIELD... [--rate HZ] --duration S --out FILE.csv
    gyroctl --port PORT load-params FILE [--merge]   a parameter set file (docs/param-set.md)
                                                 into flash: checked first, then drive
                                                 off, defaults, set, save, drive on again
    gyroctl plot FILE.csv [--columns A,B] [--t-start S] [--t-end S] [--out FILE.png]

--timeout S is how long every command waits for its reply, and how long `log` waits
without a record (plus two record periods, scaled by the emulator's stretch). The first
command of each call is resent until the gyro answers (a booting emulator drops it).

PORT: a serial device, a pty (gyro-sim, fw_pty_host) or a pyserial URL
(socket://127.0.0.1:PORT); default $GYROCTL_PORT.

Exit status: 0 the gyro answered ok; 1 it answered err (the err line is on stderr);
2 usage, or a bad parameter-set file (nothing sent); 3 the port cannot be opened or the
gyro does not answer; 4 a log, plot or sweep export failed (the sweep failed or did not
finish).
Data lines of a reply are printed without their "- " prefix, then the ok text.
"""

from __future__ import annotations

import argparse
import os
import sys

from gyrotools import paramset

from . import load_params, logger, shell
from . import plot as plot_mod
from . import sweep as sweep_mod
from .client import Client
from .link import CommandError, Link, LinkError

SIMPLE = ("save", "load", "defaults", "diff", "status", "version", "help", "stop", "sweep",
          "selftest")


def _parser():
    ap = argparse.ArgumentParser(prog="gyroctl", description="Tune, save and log the gyro over its UART.",
                                 epilog="Exit status: 0 ok, 1 the gyro answered err, 2 usage, "
                                        "3 no port or no answer, 4 log/plot failure.")
    ap.add_argument("--port", default=os.environ.get("GYROCTL_PORT"),
                    help="device, pty path or pyserial URL (default $GYROCTL_PORT)")
    ap.add_argument("--timeout", type=float, default=3.0, metavar="S",
                    help="seconds to wait for the port and each reply, and the silence "
                         "`log` allows (default 3; scaled by the emulator's stretch in log)")
    sub = ap.add_subparsers(dest="cmd", required=True, metavar="COMMAND")
    sub.add_parser("shell", help="interactive command line")
    p = sub.add_parser("get", help="print a parameter's value")
    p.add_argument("name")
    p = sub.add_parser("set", help="set parameters (all or nothing)")
    p.add_argument("pairs", nargs=argparse.REMAINDER, metavar="NAME VALUE")
    for c in SIMPLE:
        sub.add_parser(c, help=f"the gyro's `{c}` command")
    p = sub.add_parser("list", help="parameters with value, unit, range, default, flags")
    p.add_argument("prefix", nargs="?")
    p = sub.add_parser("drive", help="start or stop the drive")
    p.add_argument("state", choices=("on", "off"))
    sub.add_parser("fields", help="the telemetry fields `log` can record, with type and unit")
    p = sub.add_parser("log", help="record a telemetry stream to CSV")
    p.add_argument("fields", nargs="+", metavar="FIELD")
    p.add_argument("--rate", type=float, default=None, help="Hz (default: the gyro's tlm.rate_hz)")
    p.add_argument("--duration", type=float, required=True,
                   help="seconds of gyro time (the stream's clock, not the wall clock)")
    p.add_argument("--out", required=True, help="CSV file")
    p.add_argument("--strict", action="store_true", help="exit 4 if any record or frame was lost")
    p = sub.add_parser("sweep-csv", help="the self-calibration sweep's measured points as the "
                                         "frequency-response CSV gyro-freqresp reads")
    p.add_argument("--out", required=True, help="CSV file (f_hz, amp, phase_deg, ...)")
    p.add_argument("--run", action="store_true",
                   help="run a sweep first and wait for it (the drive is re-identified and "
                        "its loops redesigned, as with `sweep`)")
    p.add_argument("--sweep-timeout", type=float, default=120.0, metavar="S",
                   help="with --run: wall-clock seconds to wait for the sweep (default 120)")
    p = sub.add_parser(
        "load-params", help="load a parameter set file into the gyro's flash",
        description="Check a firmware parameter set (docs/param-set.md; gyro-sim --save-params "
                    "writes them), then on the gyro: status, drive off, defaults (what the set "
                    "does not list takes its default, as from flash; not with --merge), set "
                    "the entries, save, and drive on if the drive was running. A bad file "
                    "sends nothing (exit 2). A refused command stops the sequence (exit 1, the "
                    "command and the gyro's answer on stderr): the board may then hold part of "
                    "the set in RAM, unsaved, with the drive off; `gyroctl load` restores the "
                    "values in flash and `gyroctl drive on` restarts the drive.")
    p.add_argument("file", help="parameter set (JSON)")
    p.add_argument("--merge", action="store_true",
                   help="keep the gyro's values of the parameters the set does not list "
                        "(default: they take their defaults)")
    p.add_argument("--verbose", action="store_true", help="print each command and its answer")
    p = sub.add_parser("plot", help="draw a CSV log to PNG")
    p.add_argument("csv")
    p.add_argument("--out", default=None, help="PNG file (default: the CSV's name with .png)")
    p.add_argument("--columns", default=None, metavar="A,B,...",
                   help="columns to draw, comma separated (default: every column, at most "
                        f"{plot_mod.MAX_DEFAULT_PANELS})")
    p.add_argument("--t-start", type=float, default=None, metavar="S", help="from this time (s)")
    p.add_argument("--t-end", type=float, default=None, metavar="S", help="up to this time (s)")
    return ap


# The firmware's hint names its own command line; through gyroctl the list is `fields`.
FIRMWARE_HINT = "`stream` alone lists them"
GYROCTL_HINT = "`gyroctl fields` lists them"


def _print_err(reply):
    print(reply.final.replace(FIRMWARE_HINT, GYROCTL_HINT), file=sys.stderr)


def _print_reply(r):
    for d in r.data:
        print(d)
    if r.text:
        print(r.text)


def main(argv=None) -> int:
    ap = _parser()
    args = ap.parse_args(argv)
    if args.cmd == "plot":
        try:
            cols = None if args.columns is None else [c for c in args.columns.split(",") if c]
            out = plot_mod.plot(args.csv, args.out, columns=cols, t_start=args.t_start,
                                t_end=args.t_end)
        except plot_mod.PlotError as e:
            print(f"gyroctl: {e}", file=sys.stderr)
            return 4
        print(out)
        return 0
    if not args.port:
        ap.error("--port is required (or set GYROCTL_PORT)")
    if args.cmd == "set" and (len(args.pairs) == 0 or len(args.pairs) % 2 != 0):
        ap.error("set takes NAME VALUE pairs")
    if not args.timeout > 0:
        ap.error("--timeout must be > 0")
    pset = None
    if args.cmd == "load-params":
        try:
            pset = paramset.read(args.file)
        except paramset.ParamSetError as e:
            print(f"gyroctl: load-params: {e} (nothing sent)", file=sys.stderr)
            return 2
    try:
        with Link(args.port, timeout_s=args.timeout) as link:
            link.sync()
            if pset is not None:
                return _load_params(args, link, pset)
            return _run(args, link)
    except CommandError as e:
        _print_err(e.reply)
        return 1
    except LinkError as e:
        print(f"gyroctl: {e}", file=sys.stderr)
        return 3
    except (logger.LogError, sweep_mod.SweepError, OSError) as e:
        print(f"gyroctl: {e}", file=sys.stderr)
        return 4


def _load_params(args, link, pset) -> int:
    say = (lambda m: print(f"gyroctl: {m}", file=sys.stderr)) if args.verbose else None
    try:
        res = load_params.load(link, pset, merge=args.merge, progress=say)
    except load_params.LoadError as e:
        print(f"gyroctl: load-params: {e}; the gyro may hold part of the set unsaved, with the "
              "drive off (`gyroctl load` restores flash, `gyroctl drive on` the drive)", file=sys.stderr)
        return 1
    again = "; drive on again" if res["was_running"] else ""
    print(f"{len(pset.entries)} parameters from {args.file}: {res['saved']}{again}")
    return 0


def _run(args, link) -> int:
    client = Client(link)
    if args.cmd == "shell":
        return shell.run(link)
    if args.cmd == "log":
        res = logger.log(link, args.fields, args.rate, args.duration, args.out,
                         progress=logger.progress_for(sys.stderr), timeout_s=args.timeout)
        print(f"gyroctl: log: {res.summary()}", file=sys.stderr)
        return 4 if (args.strict and not res.clean) else 0
    if args.cmd == "sweep-csv":
        n = sweep_mod.export(link, args.out, run=args.run, timeout_s=args.sweep_timeout,
                             progress=lambda m: print(f"gyroctl: {m}", file=sys.stderr))
        print(f"gyroctl: sweep-csv: {n} points to {args.out}", file=sys.stderr)
        print(args.out)
        return 0
    if args.cmd == "fields":
        for name, ftype, unit in client.fields():
            print(f"{name:16s} {ftype:4s} {unit}")
        return 0
    if args.cmd == "get":
        print(client.get(args.name))
        return 0
    if args.cmd == "set":
        line = "set " + " ".join(args.pairs)
    elif args.cmd == "list":
        line = "list" + (f" {args.prefix}" if args.prefix else "")
    elif args.cmd == "drive":
        line = f"drive {args.state}"
    else:
        line = args.cmd
    r = link.command(line)
    if not r.ok:
        raise CommandError(r)
    _print_reply(r)
    return 0
