"""A serial link to the gyro's tuning UART speaking the command-line protocol.

PORT is anything pyserial opens: a device (/dev/ttyUSB0), a pseudo-terminal of the
simulator or of tests/e2e/fw_pty_host (/dev/pts/N), or a URL such as
socket://127.0.0.1:PORT (the emulated board). 921600 8N1.

Protocol (firmware/comm/cli.h): one line per command; the reply is zero or more
"- ..." data lines and one final "ok [...]" or "err CODE message" line. Telemetry frames
may arrive at any time in between (firmware/comm/tlm_frame.h); every received byte goes
through one frames.Decoder, which hands text lines to the reply reader and frames to
whoever listens (on_header / on_data).
"""

from __future__ import annotations

import collections
import dataclasses
import time

from . import frames

BAUD = 921600
LINE_MAX = 120  # firmware/comm/cli.h CLI_LINE_MAX


class LinkError(Exception):
    """The port cannot be opened, or the gyro did not answer."""


class CommandError(Exception):
    """The gyro answered `err CODE message`."""

    def __init__(self, reply):
        super().__init__(reply.final)
        self.reply = reply


@dataclasses.dataclass
class Reply:
    final: str   # the ok/err line
    data: list   # the "- " lines, without the prefix

    @property
    def ok(self) -> bool:
        return self.final == "ok" or self.final.startswith("ok ")

    @property
    def text(self) -> str:
        """What follows "ok " (ok replies) or "err " (err replies)."""
        return self.final[3:] if self.ok else self.final[4:]

    @property
    def code(self):
        return None if self.ok else self.final.split(" ", 2)[1]


def is_final(line: str) -> bool:
    return line == "ok" or line.startswith("ok ") or line.startswith("err ")


class Link:
    def __init__(self, port: str, timeout_s: float = 3.0, on_header=None, on_data=None, serial_obj=None):
        self.port = port
        self.timeout_s = timeout_s
        self.on_header, self.on_data = on_header, on_data
        self._lines = collections.deque()
        self.decoder = frames.Decoder(self._text, self._header, self._data)
        if serial_obj is not None:
            self.ser = serial_obj
        else:
            try:
                import serial  # pyserial
            except ImportError as e:  # pragma: no cover - setup.sh installs it
                raise LinkError("pyserial is not installed (tools/setup.sh)") from e
            try:
                self.ser = serial.serial_for_url(port, baudrate=BAUD, timeout=0.02)
            except (serial.SerialException, ValueError, OSError) as e:
                raise LinkError(f"cannot open {port}: {e}") from None

    # ---- receiving ----
    def _text(self, line):
        self._lines.append(line)

    def _header(self, layout):
        if self.on_header:
            self.on_header(layout)

    def _data(self, frame):
        if self.on_data:
            self.on_data(frame)

    def poll(self) -> int:
        """Read what has arrived (waiting up to the port's 20 ms timeout for a first
        byte) and decode it. Returns the number of bytes read."""
        try:
            n = self.ser.in_waiting
            if n == 0:
                data = self.ser.read(1)
                if data:
                    data += self.ser.read(self.ser.in_waiting)
            else:
                data = self.ser.read(n)
        except OSError as e:
            raise LinkError(f"{self.port}: {e}") from None
        except Exception as e:  # serial.SerialException and friends
            raise LinkError(f"{self.port}: {e}") from None
        if data:
            self.decoder.feed(data)
        return len(data)

    def drain(self, quiet_s: float = 0.05, max_s: float = 1.0):
        """Read and drop text until no line has arrived for quiet_s (frames of a running
        stream still go to the listeners and do not keep it waiting)."""
        t_end = time.monotonic() + max_s
        st = self.decoder.stats
        seen = (st.lines, st.lines_bad)
        last = time.monotonic()
        while time.monotonic() < t_end:
            self.poll()
            now = (st.lines, st.lines_bad)
            if now != seen:
                seen, last = now, time.monotonic()
            elif time.monotonic() - last >= quiet_s:
                break
        self._lines.clear()

    def sync(self):
        """Start clean: an empty line ends whatever partial line the gyro holds (its reply,
        if any, is dropped with anything else pending)."""
        self.write(b"\n")
        self.drain()

    # ---- sending ----
    def write(self, data: bytes):
        try:
            self.ser.write(data)
            self.ser.flush()
        except Exception as e:
            raise LinkError(f"{self.port}: {e}") from None

    def command(self, line: str, timeout_s: float | None = None, check: bool = False) -> Reply:
        """Send one command line and return its reply. check: raise CommandError on err."""
        if "\r" in line or "\n" in line:
            raise ValueError("one line per command")
        self._lines.clear()
        self.write(line.encode("ascii", errors="replace") + b"\n")
        reply = self.read_reply(timeout_s, what=line)
        if check and not reply.ok:
            raise CommandError(reply)
        return reply

    def read_reply(self, timeout_s: float | None = None, what: str = "the command") -> Reply:
        t_end = time.monotonic() + (self.timeout_s if timeout_s is None else timeout_s)
        data = []
        while True:
            while self._lines:
                line = self._lines.popleft()
                if line.startswith("- "):
                    data.append(line[2:])
                elif is_final(line):
                    return Reply(line, data)
                # anything else is not part of the reply grammar: ignored
            if time.monotonic() > t_end:
                raise LinkError(f"no reply to '{what}' from {self.port}")
            self.poll()

    def close(self):
        try:
            self.ser.close()
        except Exception:
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
