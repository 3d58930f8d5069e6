"""`gyroctl shell`: the gyro's command line, interactively, with tab completion of
command names (from `help`), parameter names (from `list`) and stream fields (from
`stream`). Lines go to the gyro as typed; replies are printed as received. `exit`,
`quit` or end of input leave. Without a terminal, commands are read from stdin (one per
line) and no prompt is shown, so the shell also scripts."""

from __future__ import annotations

import sys

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
    while True:
        try:
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
            status = 1
    if interactive:
        stdout.write("\n")
    return status
