"""gyroctl's pieces without a device: the CSV logger driven by a scripted fake port (the
reply and the frames arrive in one read, a gap of lost records), value formatting and
column names, the shell's completion, the reply grammar, the plot reader."""

import struct

import pytest

from gyroctl_lib import frames, logger, plot, shell
from gyroctl_lib.link import Link, LinkError, Reply


def header(stream_id, decim, fields, seq=0):
    p = struct.pack("<BIIIHIIB", 1, stream_id, 50000, decim, 10, 0, 0, len(fields))
    for name, t in fields:
        p += bytes([t, len(name)]) + name.encode()
    return frames.to_wire(frames.seal(frames.TYPE_HEADER, seq, p))


def data(stream_id, first, recs, seq):
    p = struct.pack("<HIB", stream_id & 0xFFFF, first, len(recs))
    for rate, flags in recs:
        p += struct.pack("<fI", rate, flags)
    return frames.to_wire(frames.seal(frames.TYPE_DATA, seq, p))


class FakePort:
    """A pyserial stand-in: answers `stream` with its reply and all its frames in one
    burst, `stop` with the stop reply; anything else with err."""

    def __init__(self):
        self.rx = bytearray()
        self.timeout = 0.02
        self.sent = []

    @property
    def in_waiting(self):
        return len(self.rx)

    def read(self, n):
        out = bytes(self.rx[:n])
        del self.rx[:n]
        return out

    def write(self, b):
        line = b.decode().strip()
        self.sent.append(line)
        if line.startswith("stream"):
            self.rx += b"ok stream 5 1000 Hz decim 50 fields 2 per_frame 10 link 1 B/s 0%\r\n"
            self.rx += header(5, 50, [("rate_dps", 0), ("flags", 1)])
            seq = 1
            for first in range(0, 130, 10):
                if first == 30:
                    seq += 1
                    continue  # a frame lost: records 30..39 missing
                self.rx += data(5, first, [(0.5 * k, k) for k in range(first, first + 10)], seq)
                seq += 1
        elif line == "stop":
            self.rx += b"ok stop 5 records 120 lost 0 frames 13 dropped 0\r\n"
        elif line:
            self.rx += b"err UNKNOWN no\r\n"

    def flush(self):
        pass

    def close(self):
        pass


def test_logger_with_scripted_port(tmp_path):
    port = FakePort()
    link = Link("fake", serial_obj=port)
    out = tmp_path / "x.csv"
    res = logger.log(link, ["rate_dps", "flags"], 1000, 0.1, out, timeout_s=5)
    assert port.sent == ["emu", "stream rate_dps flags @1000", "stop"]  # emu: no stretch here
    rows = [ln for ln in out.read_text().splitlines() if ln and not ln.startswith("#")]
    assert rows[0] == "t_s,rate_dps,flags"
    body = [r.split(",") for r in rows[1:]]
    idx = [round(float(r[0]) * 1000) for r in body]
    assert idx == [k for k in range(100) if not 30 <= k < 40]  # 0.1 s at 1 kHz, gap kept
    assert all(float(r[1]) == 0.5 * k and r[2] == "%d" % k for r, k in zip(body, idx))
    assert (res.wanted, res.rows, res.missing, res.frames_missing) == (100, 90, 10, 1)
    assert not res.clean
    assert "missing records 10, frames missing 1" in out.read_text()


def test_logger_refused_stream(tmp_path):
    class Refuse(FakePort):
        def write(self, b):
            self.rx += b"err NAME no field 'x'\r\n"

    link = Link("fake", serial_obj=Refuse())
    with pytest.raises(Exception) as e:
        logger.log(link, ["x"], 100, 1, tmp_path / "y.csv", timeout_s=1)
    assert "err NAME" in str(e.value)


def test_no_reply_is_a_link_error():
    class Mute(FakePort):
        def write(self, b):
            pass

    link = Link("fake", timeout_s=0.2, serial_obj=Mute())
    with pytest.raises(LinkError):
        link.command("status")


def test_columns_and_values():
    assert logger.column_name("drive_amp_v") == "drive_amp"
    assert logger.column_name("rate_dps") == "rate_dps"
    assert logger.field_name("drive_amp") == "drive_amp_v"
    assert logger.format_value("flags", frames.T_U32, 9) == "9"
    assert logger.format_value("tick", frames.T_U32, 9) == "9"
    x = struct.unpack("<f", struct.pack("<f", 0.1))[0]
    assert struct.unpack("<f", struct.pack("<f", float(logger.format_value("p_deg", frames.T_F32, x))))[0] == x


def test_reply_grammar():
    assert Reply("ok", []).ok and Reply("ok", []).text == ""
    r = Reply("err RANGE drive.amp_set_v: 99 outside [0.05,4.5] V", [])
    assert not r.ok and r.code == "RANGE" and r.text.startswith("RANGE ")


def test_shell_completion():
    c = shell.Completer(["get", "set", "list", "stream", "status", "drive"],
                        ["drive.amp_set_v", "drive.freq_hz", "rate.scale_dps"], ["rate_dps", "tick"])
    assert c.candidates("st", "st") == ["status", "stream"]
    assert c.candidates("get drive.", "drive.") == ["drive.amp_set_v", "drive.freq_hz"]
    assert c.candidates("set drive.freq_hz 1500 ra", "ra") == ["rate.scale_dps"]
    assert c.candidates("set drive.freq_hz ", "") == []  # a value goes here
    assert c.candidates("stream rate_dps ", "") == ["rate_dps", "tick", "all"]
    assert c.candidates("drive ", "") == ["on", "off"]
    assert c.candidates("", "") == sorted(["get", "set", "list", "stream", "status", "drive", "exit", "quit"])


def test_plot_reader(tmp_path):
    p = tmp_path / "a.csv"
    p.write_text("# comment\nt_s,rate_dps,flags\n0,1.5,0x3\n0.001,2.5,0x10\n# end\n")
    header, cols = plot.read_csv(p)
    assert header == ["t_s", "rate_dps", "flags"]
    assert cols == [[0.0, 0.001], [1.5, 2.5], [3.0, 16.0]]
    p.write_text("t_s,a\n0,x\n")
    with pytest.raises(plot.PlotError):
        plot.read_csv(p)
