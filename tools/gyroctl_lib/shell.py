"""`gyroctl shell`: the gyro's command line, interactively, with tab completion of
command names (from `help`), parameter names (from `list`) and stream fields (from
`stream`). Lines go to the gyro as typed; replies are printed as received. `exit`,
`quit` or end of input leave. Without a terminal, commands are read from stdin (one per
line) and no prompt is shown, so the shell also scripts.

`stream FIELD...` shows the values as they arrive (about SHOW_HZ records per second of
wall time, so a terminal keeps up) until the next line of input: an empty line (Enter)
or Ctrl-C sends `stop`; a command is run after the `stop`."""

from __future__ import annotations

import select
import sys
import time

from .client import Client
from .link import CommandError, LinkError

LOCAL = ("exit", "quit")


class Completer:
    def __init__(self, commands, params, fields):
        self.commands = sorted(set(commands) | set(LOCAL))
        self.params = sorted(params)
        self.fields = sorted(fields) + ["all"]
        self._matches = []

    def candidates(self, line: str, text: str) -> list:
        """Completions of the word `text` at the end of `line`."""
        words = line.split()
        if line.endswith((" ", "\t")) or not words:
            pos = len(words)
        else:
            pos = len(words) - 1
        if pos == 0:
            pool = self.commands
        else:
            cmd = words[0]
            if cmd in ("get", "list") and pos == 1:
                pool = self.params
            elif cmd == "set" and pos % 2 == 1:
                pool = self.params
            elif cmd == "stream":
                pool = self.fields
            elif cmd == "drive" and pos == 1:
                pool = ["on", "off"]
            else:
                pool = []
        return [c for c in pool if c.startswith(text)]

    def complete(self, text, state):
        if state == 0:
            import readline
            self._matches = self.candidates(readline.get_line_buffer()[:readline.get_endidx()], text)
        return self._matches[state] if state < len(self._matches) else None


def load_completer(client: Client) -> Completer:
    try:
        commands = client.commands()
    except (CommandError, LinkError):
        commands = []
    try:
        params = [p.name for p in client.params()]
    except (CommandError, LinkError):
        params = []
    try:
        fields = [f[0] for f in client.fields()]
    except (CommandError, LinkError):
        fields = []
    return Completer(commands, params, fields)


SHOW_HZ = 10.0


class _Viewer:
    """Prints the records of a running stream as rows under a header of field names."""

    def __init__(self, out):
        self.out, self.layout, self.next_t = out, None, 0.0
        self.held = []  # rows decoded with the `stream` reply, shown after it

    def write(self, text):
        if self.held is None:
            self.out.write(text)
        else:
            self.held.append(text)

    def release(self):
        for text in self.held or []:
            self.out.write(text)
        self.held = None

    def on_header(self, lay):
        if self.layout is None or lay.stream_id != self.layout.stream_id:
            self.layout = lay
            self.write("t_s        " + " ".join(f"{n:>14s}" for n in lay.names) + "\n")

    def on_data(self, fr):
        if self.layout is None or fr.layout.stream_id != self.layout.stream_id:
            return
        now = time.monotonic()
        if now < self.next_t or not fr.records:
            return
        self.next_t = now + 1.0 / SHOW_HZ
        idx = fr.first_rec + len(fr.records) - 1
        cells = " ".join(f"{v:14.6g}" for v in fr.records[-1])
        self.write(f"{self.layout.time_s(idx):<10.3f} {cells}\n")
        self.out.flush()


def _watch_stream(link, viewer, stdin, stdout):
    """Show the stream until a line of input (or its end, or Ctrl-C), then stop it.
    Returns the line read ('' at an empty line, None at end of input)."""
    viewer.release()
    line = None
    try:
        while True:
            link.poll()
            try:
                ready = select.select([stdin], [], [], 0)[0]
            except (ValueError, OSError, TypeError):  # no file descriptor: no way to wait
                ready = [stdin]
            if ready:
                line = stdin.readline()
                line = None if line == "" else line.strip()
                break
    except KeyboardInterrupt:
        line = ""
    finally:
        link.on_header = link.on_data = None
    r = link.command("stop")
    stdout.write(r.final + "\n")
    return line


def _is_stream_start(line: str) -> bool:
    w = line.split()
    return len(w) > 1 and w[0] == "stream"


def run(link, stdin=None, stdout=None) -> int:
    stdin = stdin or sys.stdin
    stdout = stdout or sys.stdout
    interactive = stdin.isatty()
    client = Client(link)
    if interactive:
        try:
            import readline
            comp = load_completer(client)
            readline.set_completer_delims(" \t")
            readline.set_completer(comp.complete)
            readline.parse_and_bind("tab: complete")
        except ImportError:  # pragma: no cover
            pass
    status = 0
    queued = None
    while True:
        try:
            if queued is not None:
                line, queued = queued, None
            else:
                line = input("gyro> ") if interactive else stdin.readline()
        except EOFError:
            break
        except KeyboardInterrupt:
            stdout.write("\n")
            continue
        if not interactive and line == "":
            break
        line = line.strip()
        if not line:
            continue
        if line in LOCAL:
            break
        viewer = None
        if _is_stream_start(line):
            # Listen before sending: the first frames come in the same read as the reply.
            viewer = _Viewer(stdout)
            link.on_header, link.on_data = viewer.on_header, viewer.on_data
        try:
            r = link.command(line)
        except LinkError as e:
            print(f"gyroctl: {e}", file=sys.stderr)
            return 3
        for d in r.data:
            stdout.write(f"- {d}\n")
        stdout.write(r.final + "\n")
        stdout.flush()
        if not r.ok:
            link.on_header = link.on_data = None
            status = 1
        elif viewer is not None:
            try:
                nxt = _watch_stream(link, viewer, stdin, stdout)
            except LinkError as e:
                print(f"gyroctl: {e}", file=sys.stderr)
                return 3
            if nxt is None:
                break
            queued = nxt or None
    if interactive:
        stdout.write("\n")
    return status
