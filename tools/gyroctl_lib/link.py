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
import errno
import time

from . import frames

BAUD = 921600
LINE_MAX = 120  # firmware/comm/cli.h CLI_LINE_MAX
SYNC_LINE = "version"      # harmless, answered in every mode
SYNC_REPLY = "ok fw "      # how its reply starts (firmware/comm/cli_builtin.c)
RESEND_S = 1.0             # resend the sync line after this long without a reply
MACHINE_LINE = "console off"  # machine mode: no prompt, no echo (firmware/comm/cli.h)
GONE = ("the gyro went away (port closed: the simulator or emulator ended, the cable was "
        "unplugged, or the board reset)")


def _open_error(port, e):
    """Why a port cannot be opened, in words a user can act on; None: try again (the
    port is not there yet, e.g. a simulator or emulator still starting)."""
    text = str(e)
    code = getattr(e, "errno", None)
    if "exclusively lock" in text or code in (errno.EBUSY, errno.EAGAIN):
        return (f"{port} is in use by another program (a terminal such as picocom, or "
                "another gyroctl): close it first")
    if code == errno.ENOENT or "No such file" in text or "Connection refused" in text:
        return None
    if code == errno.EACCES or "Permission denied" in text:
        return f"cannot open {port}: permission denied (is the user in group dialout?)"
    return f"cannot open {port}: {text}"


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
        self._stale_sync = 0  # sync lines resent whose late replies are still due
        self.ser = serial_obj if serial_obj is not None else self._open()

    def _open(self):
        """Open the port, waiting up to timeout_s for it to appear (a pty or TCP port of
        a simulator or emulator that is still starting). A local device is opened
        exclusively, so a second client gets a clear refusal instead of stolen replies."""
        try:
            import serial  # pyserial
        except ImportError as e:  # pragma: no cover - setup.sh installs it
            raise LinkError("pyserial is not installed (tools/setup.sh)") from e
        local = "://" not in self.port
        deadline = time.monotonic() + self.timeout_s
        while True:
            try:
                if local:
                    return serial.serial_for_url(self.port, baudrate=BAUD, timeout=0.02,
                                                 exclusive=True)
                return serial.serial_for_url(self.port, baudrate=BAUD, timeout=0.02)
            except (serial.SerialException, ValueError, OSError) as e:
                msg = _open_error(self.port, e)
                if msg is not None:
                    raise LinkError(msg) from None
                if time.monotonic() > deadline:
                    what = "nothing listens" if "Connection refused" in str(e) else "no such port"
                    raise LinkError(f"cannot open {self.port}: {what}, not there after "
                                    f"{self.timeout_s:g} s of waiting") from None
            time.sleep(0.1)

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
        except Exception:  # OSError (EIO: pty closed), serial.SerialException (socket closed)
            raise LinkError(f"{self.port}: {GONE}") from None
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
        """Start clean, and make sure the gyro listens: an empty line ends whatever partial
        line it holds, then a harmless command is sent, and resent every RESEND_S, until
        the first reply (a booting emulator drops what arrives before its UART is up)
        or timeout_s. Late replies to the resent lines are dropped by read_reply. Then
        the port is put in machine mode (MACHINE_LINE, once)."""
        self.write(b"\n")
        deadline = time.monotonic() + self.timeout_s
        sends = 0
        while True:
            self._lines.clear()
            self.write(SYNC_LINE.encode() + b"\n")
            sends += 1
            t_resend = min(deadline, time.monotonic() + RESEND_S)
            if self._wait_final(t_resend):
                break
            if time.monotonic() >= deadline:
                raise LinkError(self._no_reply_message(f"'{SYNC_LINE}'"))
        self._stale_sync = sends - 1
        # A person at a terminal may have left the port in console mode (prompt, echo):
        # back to machine mode, one reply per line. Whatever the answer (an older
        # firmware has no such command: err UNKNOWN), the link goes on.
        self.command(MACHINE_LINE)
        self.drain()

    def _wait_final(self, t_end) -> bool:
        while time.monotonic() < t_end:
            self.poll()
            if any(is_final(ln) for ln in self._lines):
                return True
        return False

    def _no_reply_message(self, what) -> str:
        msg = f"no reply to {what} from {self.port} within {self.timeout_s:g} s"
        if "://" in self.port:
            # QEMU's TCP serial port serves one client; a second one connects but hears nothing.
            msg += " (is another client connected? the emulator serves one at a time)"
        else:
            msg += " (is the gyro powered and running, at 921600 8N1?)"
        return msg

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
                    if self._stale_sync and line.startswith(SYNC_REPLY) and what != SYNC_LINE:
                        self._stale_sync -= 1  # a late answer to a resent sync line
                        data = []
                        continue
                    return Reply(line, data)
                # anything else is not part of the reply grammar: ignored
            if time.monotonic() > t_end:
                raise LinkError(self._no_reply_message(f"'{what}'"))
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
