"""What the command-line scripts share: one-line errors, the output folder, JSON.

A user error (InputError, a bad option, an unwritable output folder) prints one line
"<prog>: error: ..." on stderr and exits with status 2; no traceback. Anything else is a
bug in the tool and keeps its traceback.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shlex
import sys

import numpy as np

from .errors import InputError  # noqa: F401  (re-exported for the scripts)


class Parser(argparse.ArgumentParser):
    """argparse with a one-line error message."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")

    def parse_args(self, args=None, namespace=None):
        """The options, with the command line as given kept for invocation()."""
        argv = list(sys.argv[1:] if args is None else args)
        ns = super().parse_args(argv, namespace)
        ns.argv_ = argv
        ns.prog_ = self.prog
        return ns


def invocation(a):
    """What a tool's JSON records of how it was run: the command line as given (by a person
    or by gyro-sim's analyses) and every option's value, defaults included, so that a
    figure can be made again from its file alone."""
    opts = {k: v for k, v in vars(a).items() if not k.endswith("_")}
    return {"command": " ".join([a.prog_] + [shlex.quote(x) for x in a.argv_]),
            "options": opts}


def parser(prog, description):
    p = Parser(prog=prog, description=description)
    p.add_argument("--out", metavar="DIR", default=".",
                   help="folder for the PNG and JSON files (created if missing; default .)")
    return p


def add_window(p):
    p.add_argument("--t-start", type=float, metavar="S", default=None,
                   help="ignore rows before this time (s)")
    p.add_argument("--t-end", type=float, metavar="S", default=None,
                   help="ignore rows after this time (s)")


def out_dir(path):
    try:
        os.makedirs(path, exist_ok=True)
    except OSError as e:
        raise InputError(f"{path}: cannot create output folder ({e.strerror})") from None
    if not os.access(path, os.W_OK):
        raise InputError(f"{path}: output folder is not writable")
    return path


def _plain(x):
    """numpy scalars/arrays -> Python; NaN/inf -> None (JSON has no NaN)."""
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return [_plain(v) for v in x.tolist()]
    if isinstance(x, (np.bool_, bool)):
        return bool(x)
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, (np.floating, float)):
        x = float(x)
        return x if math.isfinite(x) else None
    return x


def write_json(directory, name, obj):
    path = os.path.join(directory, name)
    try:
        with open(path, "w", encoding="utf-8") as fh:
            json.dump(_plain(obj), fh, indent=1, allow_nan=False)
            fh.write("\n")
    except OSError as e:
        raise InputError(f"{path}: cannot write ({e.strerror})") from None
    return path


def write_text(path, text):
    """Write a text output file; a missing folder is created."""
    d = os.path.dirname(path)
    if d:
        out_dir(d)
    try:
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(text)
    except OSError as e:
        raise InputError(f"{path}: cannot write ({e.strerror})") from None
    return path


def fmt(x, digits=4):
    """Number for the printed summary; None prints as 'n/a'."""
    if x is None:
        return "n/a"
    return f"{x:.{digits}g}"


def run(main, argv=None):
    """Call main(argv); turn user errors into one line on stderr and exit status 2."""
    prog = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else "gyrotools"
    try:
        code = main(argv)
    except InputError as e:
        print(f"{prog}: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    return 0 if code is None else int(code)
