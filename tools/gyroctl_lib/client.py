"""Command helpers over a Link: parameters, commands and stream fields as Python data."""

from __future__ import annotations

import dataclasses

from .link import CommandError


@dataclasses.dataclass
class Param:
    name: str
    value: str
    unit: str
    range: str
    default: str
    flags: str
    help: str


def parse_list_line(line: str) -> Param:
    """NAME VALUE UNIT RANGE def=DEFAULT flags=FLAGS HELP (firmware/comm/cli.h)."""
    parts = line.split(" ", 6)
    while len(parts) < 7:
        parts.append("")
    name, value, unit, rng, default, flags, hlp = parts
    return Param(name, value, unit, rng, default.removeprefix("def="), flags.removeprefix("flags="), hlp)


class Client:
    def __init__(self, link):
        self.link = link

    def run(self, line: str):
        return self.link.command(line)

    def get(self, name: str) -> str:
        """The value as the gyro prints it (round-trips exactly through set)."""
        r = self.link.command(f"get {name}", check=True)
        parts = r.text.split(" ")
        if len(parts) < 2 or parts[0] != name:
            raise CommandError(r)
        return parts[1]

    def set(self, pairs) -> dict:
        words = " ".join(f"{n} {v}" for n, v in pairs)
        r = self.link.command(f"set {words}", check=True)
        t = r.text.split(" ")
        return dict(zip(t[0::2], t[1::2]))

    def params(self, prefix: str = "") -> list:
        r = self.link.command(f"list {prefix}".strip(), check=True)
        return [parse_list_line(d) for d in r.data]

    def commands(self) -> list:
        """Command names from `help` (built-in and the application's)."""
        r = self.link.command("help", check=True)
        return [d.split(" ", 1)[0] for d in r.data if d]

    def fields(self) -> list:
        """Streamable fields [(name, type, unit)] from `stream` without arguments."""
        r = self.link.command("stream", check=True)
        out = []
        for d in r.data:
            p = d.split(" ")
            if len(p) >= 3:
                out.append((p[0], p[1], p[2]))
        return out
