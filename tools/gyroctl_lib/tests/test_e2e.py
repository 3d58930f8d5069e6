"""gyroctl end to end against the real application behind a pty (tests/e2e/fw_pty_host:
app_init, the sample ISR through the host HAL with a silent plant, app_poll, the pty
bridge), with the parameter flash in a file:

  get/set round trip; bad values (text, 1e999, nan, out of range, unknown name) and bad
  lines (overlong, NUL bytes, binary garbage) answered with err and changing nothing;
  a 1 kHz stream logged to CSV with the analysis tools' columns and nothing lost;
  save refused while the drive runs, accepted after `drive off`; the program restarted
  over the same flash file loads the saved value; the interactive shell scripted
  through stdin; plot of the log.
"""

import csv
import io
import subprocess
import sys

import pytest

from gyroctl_lib import cli
from gyroctl_lib.link import Link


class Host:
    def __init__(self, exe, flash):
        self.proc = subprocess.Popen([exe, "--flash", str(flash)], stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True)
        line = self.proc.stdout.readline().split()
        if len(line) != 2 or line[0] != "pty":
            self.stop()
            pytest.fail(f"fw_pty_host did not start: {line} {self.proc.stderr.read()}")
        self.port = line[1]

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        assert self.proc.returncode == 0, self.proc.stderr.read()


@pytest.fixture
def host(fw_pty_host, tmp_path):
    h = Host(fw_pty_host, tmp_path / "flash.bin")
    yield h
    h.stop()


def run(gyroctl, port, *args, stdin=None):
    """The gyroctl executable, as a user runs it."""
    return subprocess.run(gyroctl + ["--port", port] + list(args), capture_output=True, text=True,
                          input=stdin, timeout=60)


class InProcess:
    """gyroctl's main() in this interpreter (the same code as the executable, without a
    Python start-up per call): returns (exit status, stdout, stderr)."""

    def __init__(self, capsys, monkeypatch, port):
        self.capsys, self.monkeypatch, self.port = capsys, monkeypatch, port

    def __call__(self, *args, stdin=None):
        if stdin is not None:
            self.monkeypatch.setattr(sys, "stdin", io.StringIO(stdin))
        self.capsys.readouterr()
        rc = cli.main(["--port", self.port] + list(args))
        out, err = self.capsys.readouterr()
        return rc, out, err


def test_tuning_session(host, gyroctl, fw_pty_host, tmp_path, capsys, monkeypatch):
    port = host.port
    g = InProcess(capsys, monkeypatch, port)

    # the parameters under test: the rate bias polynomial (live, persistent, default 0)
    c0, c1 = "rate.bias_c0_dps", "rate.bias_c1_dps_per_deg"
    default = g("list", c0)[1].split(" ")[4].removeprefix("def=")

    # the executable: value on stdout, exit 0; an err line on stderr, exit 1
    r = run(gyroctl, port, "get", c0)
    assert (r.returncode, r.stdout) == (0, default + "\n")
    r = run(gyroctl, port, "set", c0, "abc")
    assert r.returncode == 1 and r.stderr.startswith("err VALUE"), r

    rc, out, _ = g("set", c0, "12.5", c1, "-1.25e-3")
    assert (rc, out) == (0, f"{c0} 12.5 {c1} -0.00125\n")
    assert g("get", c0)[1] == "12.5\n"
    diff_before = g("diff")[1]
    assert f"{c0} 12.5 default {default}" in diff_before

    # bad values: err on stderr, exit 1, nothing changed (pairs are all or nothing)
    for args, code in [((c0, "1e999"), None), ((c0, "nan"), "VALUE"), ((c0, "1e30"), "RANGE"),
                       (("nosuch.param", "1"), "NAME"), ((c1, "7", c0, "inf"), None),
                       (("sys.fs_hz", "1000"), "RO")]:
        rc, _, err = g("set", *args)
        assert rc == 1 and err.startswith("err " + (code or "")), (args, err)
    with pytest.raises(SystemExit) as e:  # odd number of words: refused before sending
        g("set", c0)
    assert e.value.code == 2
    assert g("diff")[1] == diff_before

    # bad lines straight on the wire: each answered with err, nothing changed
    with Link(port) as link:
        link.sync()
        assert link.command("x" * 200).final.startswith("err TOOLONG")
        link.write(b"set rate.bias_c0_dps\x00 3\n")
        assert link.read_reply().final.startswith("err BADCHAR")
        link.write(bytes(b for b in range(256) if b not in (10, 13)) + b"\n")
        assert link.read_reply().final.startswith("err BADCHAR")
        link.write(bytes([0x00, 0x01, 0xFF, 0x00]) * 50 + b"\r\n")
        assert link.read_reply().final.startswith("err BADCHAR")
        assert link.command(f"get {c0}").final == f"ok {c0} 12.5 deg/s"
    assert g("diff")[1] == diff_before

    # a stream logged to CSV: columns named as asked (the analysis tools read these
    # names and gyro-sim's alike), nothing lost
    out = tmp_path / "log.csv"
    rc, _, err = g("log", "rate_dps", "quad_dps", "drive_amp_v", "p_deg", "flags", "--rate", "1000",
                   "--duration", "0.5", "--out", str(out), "--strict")
    assert rc == 0, err
    assert "missing records 0, frames missing 0, corrupt frames 0, lost at source 0" in err
    rows = [row for row in csv.reader(line for line in out.read_text().splitlines()
                                      if line and not line.startswith("#"))]
    assert rows[0] == ["t_s", "rate_dps", "quad_dps", "drive_amp_v", "p_deg", "flags"]
    data = rows[1:]
    assert len(data) == 500
    assert [float(x[0]) for x in data] == pytest.approx([k / 1000.0 for k in range(500)], abs=1e-12)
    assert all(x[5].isdigit() for x in data)  # flags: decimal, as gyro-sim writes them
    png = tmp_path / "log.png"
    assert cli.main(["plot", str(out), "--out", str(png)]) == 0 and png.stat().st_size > 1000

    # a field that does not exist, and a stream over the link budget
    rc, _, err = g("log", "no_such_field", "--duration", "0.1", "--out", str(tmp_path / "x.csv"))
    assert rc == 1 and err.startswith("err NAME")
    rc, _, err = g("log", "all", "--rate", "1000", "--duration", "0.1", "--out", str(tmp_path / "x.csv"))
    assert rc == 1 and err.startswith("err BANDWIDTH")

    # the shell, scripted through stdin
    rc, out, _ = g("shell", stdin=f"get {c0}\nstatus\nbogus\n")
    assert f"ok {c0} 12.5 deg/s\n" in out
    assert "- mode " in out and "err UNKNOWN" in out
    assert rc == 1  # one command answered err

    # save needs the drive commanded off (sys.autostart started it; the trivial plant
    # never answers, so the drive cycles through ACQUIRE and a fault's wait, which does
    # not count as off)
    rc, _, err = g("save")
    assert rc == 1 and err.startswith("err BUSY")
    assert g("drive", "off")[1] == "drive off\n"
    rc, out, _ = g("save")
    assert rc == 0 and out.startswith("saved slot")

    # restart over the same flash file: the saved values load
    flash = tmp_path / "flash.bin"
    host.stop()
    h2 = Host(fw_pty_host, flash)
    try:
        g2 = InProcess(capsys, monkeypatch, h2.port)
        assert g2("get", c0)[1] == "12.5\n"
        assert g2("get", c1)[1] == "-0.00125\n"
    finally:
        h2.stop()


def test_no_port(gyroctl):
    r = subprocess.run(gyroctl + ["--port", "/nonexistent/tty", "status"], capture_output=True, text=True)
    assert r.returncode == 3 and "cannot open" in r.stderr
