"""gyroctl on a gyro that is still starting or goes away, without a device: the first
command is resent until the first reply (a booting emulator drops it) and late answers
to the resent lines are not taken for the next reply; the log's wait follows the
emulator's stretch and --timeout; a closed port, a port held by another program and a
port that appears late; a port left in console mode is put back in machine mode
once on connect (an older firmware's err UNKNOWN tolerated); the header keeps the names asked for; `stream` in the shell
shows values; the firmware's hint names a gyroctl command."""

import errno
import fcntl
import os
import struct
import threading
import time

import pytest

from gyroctl_lib import cli, frames, logger, shell
from gyroctl_lib import link as link_mod
from gyroctl_lib.link import Link, LinkError


class TimedPort:
    """A pyserial stand-in that is deaf until boot_s after creation, and answers each
    line delay_s after it was written."""

    def __init__(self, boot_s=0.0, delay_s=0.0, answers=None):
        self.t0 = time.monotonic()
        self.boot_s, self.delay_s = boot_s, delay_s
        self.answers = answers or {}
        self.queue = []          # (due time, bytes)
        self.sent = []
        self.timeout = 0.02

    def _due(self):
        now = time.monotonic()
        out = b"".join(b for t, b in self.queue if t <= now)
        self.queue = [(t, b) for t, b in self.queue if t > now]
        return out

    @property
    def in_waiting(self):
        return 0

    def read(self, n):
        time.sleep(0.005)
        return self._due()

    def write(self, b):
        line = b.decode().strip()
        self.sent.append(line)
        if not line or time.monotonic() - self.t0 < self.boot_s:
            return
        word = line.split()[0]
        reply = self.answers.get(word, b"ok fw 1.0 layout 1 format 1 params 9\r\n"
                                 if word == "version" else b"ok " + word.encode() + b"\r\n")
        self.queue.append((time.monotonic() + self.delay_s, reply))

    def flush(self):
        pass

    def close(self):
        pass


@pytest.fixture
def fast_resend(monkeypatch):
    monkeypatch.setattr(link_mod, "RESEND_S", 0.1)


def test_first_command_reaches_a_booting_gyro(fast_resend):
    port = TimedPort(boot_s=0.35)
    link = Link("fake", timeout_s=3.0, serial_obj=port)
    link.sync()
    assert port.sent.count("version") >= 4  # lost while booting, then answered
    assert link.command("status").final == "ok status"


def test_late_sync_answers_are_not_taken_for_the_reply(fast_resend):
    port = TimedPort(delay_s=0.25)  # slower than the resend period: 3 lines in flight
    link = Link("fake", timeout_s=3.0, serial_obj=port)
    link.sync()
    assert port.sent.count("version") >= 2
    assert link.command("status").final == "ok status"
    assert link.command("version").final.startswith("ok fw ")


class ConsolePort(TimedPort):
    """A gyro left in console mode by a person at a terminal: every byte echoed, a
    prompt after each reply, until "console off"."""

    def __init__(self, known=True, **kw):
        super().__init__(**kw)
        self.console, self.known = True, known

    def write(self, b):
        line = b.decode().strip()
        self.sent.append(line)
        now = time.monotonic()
        if self.console:
            self.queue.append((now, b.replace(b"\n", b"\r\n")))
        if line == "console off" and self.known:
            reply, self.console = b"ok console off\r\n", False
        elif line == "console off":
            reply = b"err UNKNOWN no command 'console'; try help\r\n"
        elif line:
            word = line.split()[0]
            reply = (b"ok fw 1.0 layout 1 format 1 params 9\r\n" if word == "version"
                     else b"ok " + word.encode() + b"\r\n")
        else:
            reply = b""
        self.queue.append((now, reply + (b"gyro> " if self.console else b"")))


def test_connect_switches_a_console_to_machine_mode(fast_resend):
    port = ConsolePort()
    link = Link("fake", timeout_s=3.0, serial_obj=port)
    link.sync()
    assert port.sent.count("console off") == 1 and not port.console
    assert link.command("status").final == "ok status"
    assert link.command("get x").final == "ok get"


def test_connect_to_a_firmware_without_console_mode(fast_resend):
    port = ConsolePort(known=False)
    port.console = False  # an older firmware: machine mode only, console unknown
    link = Link("fake", timeout_s=3.0, serial_obj=port)
    link.sync()
    assert port.sent.count("console off") == 1
    assert link.command("status").final == "ok status"


def test_connect_sends_console_off_after_the_first_reply(fast_resend):
    port = TimedPort(boot_s=0.35)  # the resync goes on as before, then machine mode once
    link = Link("fake", timeout_s=3.0, serial_obj=port)
    link.sync()
    i = port.sent.index("console off")
    assert port.sent.count("console off") == 1 and port.sent[i - 1] == "version"
    assert "console off" not in port.sent[:i]


def test_no_reply_says_what_to_check(fast_resend):
    link = Link("socket://127.0.0.1:9", timeout_s=0.3, serial_obj=TimedPort(boot_s=99))
    with pytest.raises(LinkError) as e:
        link.sync()
    assert "another client" in str(e.value)


def test_gyro_going_away_is_named():
    class Gone(TimedPort):
        def read(self, n):
            raise OSError(errno.EIO, "Input/output error")

    link = Link("/dev/pts/99", timeout_s=1.0, serial_obj=Gone())
    with pytest.raises(LinkError) as e:
        link.command("status")
    assert "went away" in str(e.value) and "Errno" not in str(e.value)


def test_port_held_by_another_program():
    master, slave = os.openpty()
    path = os.ttyname(slave)
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # what pyserial's exclusive open takes
    try:
        with pytest.raises(LinkError) as e:
            Link(path, timeout_s=0.5)
        assert "in use by another program" in str(e.value)
    finally:
        for f in (fd, slave, master):
            os.close(f)


def test_port_that_appears_late_is_waited_for(tmp_path):
    master, slave = os.openpty()
    link_path = tmp_path / "gyro.pty"
    threading.Timer(0.3, lambda: os.symlink(os.ttyname(slave), link_path)).start()
    try:
        Link(str(link_path), timeout_s=3.0).close()
        with pytest.raises(LinkError) as e:
            Link(str(tmp_path / "never"), timeout_s=0.2)
        assert "not there after" in str(e.value)
    finally:
        os.close(slave)
        os.close(master)


def _header(stream_id, names):
    p = struct.pack("<BIIIHIIB", 1, stream_id, 50000, 500, 10, 0, 0, len(names))
    for name in names:
        p += bytes([0, len(name)]) + name.encode()
    return frames.to_wire(frames.seal(frames.TYPE_HEADER, 0, p))


def _data(stream_id, first, n, seq):
    p = struct.pack("<HIB", stream_id, first, n)
    for k in range(first, first + n):
        p += struct.pack("<f", 0.25 * k)
    return frames.to_wire(frames.seal(frames.TYPE_DATA, seq, p))


class StreamPort(TimedPort):
    """`emu` answers with a stretch; `stream` starts a one-field stream of `records`."""

    def __init__(self, stretch=None, records=0, field="drive_amp_v"):
        super().__init__()
        self.stretch, self.records, self.field = stretch, records, field

    def write(self, b):
        line = b.decode().strip()
        self.sent.append(line)
        now = time.monotonic()
        if line == "emu":
            r = (b"- stretch %d\r\nok emu\r\n" % self.stretch) if self.stretch else b"err UNKNOWN emu\r\n"
        elif line.startswith("stream "):
            r = b"ok stream 7 100 Hz decim 500 fields 1 per_frame 2 link 60 B/s 0%\r\n" + _header(7, [self.field])
            for seq, first in enumerate(range(0, self.records, 10), start=1):
                r += _data(7, first, min(10, self.records - first), seq)
        elif line == "stop":
            r = b"ok stop 7 records 0 lost 0 frames 0 dropped 0\r\n"
        else:
            r = b"ok\r\n"
        self.queue.append((now, r))


def test_log_waits_by_the_emulator_stretch_and_timeout(tmp_path):
    link = Link("fake", timeout_s=1.0, serial_obj=StreamPort(stretch=32, records=5))
    t0 = time.monotonic()
    with pytest.raises(logger.LogError) as e:
        logger.log(link, ["drive_amp_v"], 100, 1.0, tmp_path / "a.csv", timeout_s=0.2)
    waited = time.monotonic() - t0
    # silence allowed: --timeout 0.2 s + 4 frames (of 2 records, per the reply) of 10 ms
    # gyro time each at stretch 32 = 0.2 + 2.56 s
    assert 2.7 < waited < 4.5, waited
    assert "5 of 100 records" in str(e.value) and "stretch 32" in str(e.value)


def test_log_header_keeps_the_names_asked_for(tmp_path):
    for asked in ("drive_amp_v", "drive_amp"):
        port = StreamPort(records=20)
        link = Link("fake", timeout_s=1.0, serial_obj=port)
        out = tmp_path / f"{asked}.csv"
        res = logger.log(link, [asked], 100, 0.2, out, timeout_s=1.0)
        assert res.rows == 20
        assert "stream drive_amp_v @100" in port.sent
        head = [ln for ln in out.read_text().splitlines() if not ln.startswith("#")][0]
        assert head == f"t_s,{asked}"


def test_progress_lines_without_a_terminal(capsys):
    import sys
    p = logger.progress_for(sys.stderr)
    for k in range(0, 101, 5):
        p(k, 100)
    err = capsys.readouterr().err
    assert [ln.split()[2] for ln in err.splitlines()] == ["25%", "50%", "75%", "100%"]


def test_shell_stream_shows_values():
    port = StreamPort(records=50, field="rate_dps")
    link = Link("fake", timeout_s=1.0, serial_obj=port)
    r, w = os.pipe()
    stdin = os.fdopen(r, "r")
    os.write(w, b"stream rate_dps @100\n")
    threading.Timer(0.4, lambda: (os.write(w, b"\nversion\n"), os.close(w))).start()

    class Out:
        text = ""

        def write(self, s):
            Out.text += s

        def flush(self):
            pass

    assert shell.run(link, stdin=stdin, stdout=Out()) == 0
    lines = Out.text.splitlines()
    assert lines[0].startswith("ok stream")
    assert lines[1].split() == ["t_s", "rate_dps"]
    t, v = (float(x) for x in lines[2].split())
    assert v == pytest.approx(0.25 * round(t * 100))  # a record: its time and value
    assert "ok stop 7 records 0 lost 0 frames 0 dropped 0" in lines
    assert port.sent[-2:] == ["stop", "version"]  # Enter stopped it, then the next line ran


def test_unknown_field_hint_names_gyroctl_fields(capsys, monkeypatch):
    class Refuse(TimedPort):
        def write(self, b):
            self.queue.append((0, b"err NAME no field 'x'; `stream` alone lists them\r\n"))

    monkeypatch.setattr(cli, "Link", lambda port, timeout_s: Link("fake", timeout_s, serial_obj=Refuse()))
    monkeypatch.setattr(Link, "sync", lambda self: None)
    assert cli.main(["--port", "fake", "log", "x", "--duration", "1", "--out", os.devnull]) == 1
    err = capsys.readouterr().err
    assert "`gyroctl fields` lists them" in err and "`stream` alone" not in err


def test_bad_timeout_is_a_usage_error():
    with pytest.raises(SystemExit) as e:
        cli.main(["--port", "x", "--timeout", "0", "status"])
    assert e.value.code == 2
