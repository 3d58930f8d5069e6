"""`gyroctl load-params` against the real application behind a pty (tests/e2e/fw_pty_host,
its flash in a file): a set written by gyrotools.paramset goes into flash (the program
restarted over the same flash loads it) and the drive is running again; what the set does
not list takes its default (or keeps the gyro's value with --merge); a bad file sends
nothing; a value the firmware refuses stops the sequence with the command named and the
flash untouched. Parameters are picked from the table, so the test holds for any list."""


import pytest
from test_e2e import Host, InProcess

from gyrotools import paramset as P
from gyrotools.tests.paramset_values import nudged

TABLE = P.load_table()
BY_NAME = P.by_name(TABLE)


def settable(kind):
    return [d for d in TABLE.values() if d.type == kind and d.settable]


@pytest.fixture
def host(fw_pty_host, tmp_path):
    h = Host(fw_pty_host, tmp_path / "flash.bin")
    yield h
    h.stop()


def value_of(g, name):
    """The gyro's value of a parameter, as the firmware holds it."""
    rc, out, _ = g("get", name)
    assert rc == 0
    return P.f32(float(out)) if BY_NAME[name].type == "F32" else int(out)


def test_load_into_flash(host, fw_pty_host, tmp_path, capsys, monkeypatch):
    g = InProcess(capsys, monkeypatch, host.port)
    # the live floats and integers whose nudged values the firmware designs with
    floats = [d for d in settable("F32") if "live" in d.flags and d.default][:6]
    u32 = settable("U32")[:1]
    values = {d.name: nudged(d) for d in floats[:-1] + u32}
    path = tmp_path / "part.json"
    P.write(path, P.from_values(values, meta={"part": "test"}))
    other = floats[-1]  # set on the gyro, not in the file: back to its default
    assert g("set", other.name, P.format_f32(nudged(other)))[0] == 0
    rc, out, err = g("load-params", str(path), "--verbose")
    assert rc == 0, err
    assert out.startswith(f"{len(values)} parameters from {path}: saved slot")
    assert "drive on again" in out  # sys.autostart started it, so it runs again
    for cmd in ("drive off", "defaults", "save", "drive on"):
        assert f"gyroctl: {cmd} -> ok" in err
    assert g("status")[1].splitlines()[-1] != "OFF"
    for name, v in values.items():
        assert value_of(g, name) == v, name
    assert value_of(g, other.name) == P.f32(other.default)

    host.stop()  # the program again over the same flash: the set was saved
    h2 = Host(fw_pty_host, tmp_path / "flash.bin")
    try:
        g2 = InProcess(capsys, monkeypatch, h2.port)
        for name, v in values.items():
            assert value_of(g2, name) == v, name
        # --merge keeps what the set does not list
        assert g2("set", other.name, P.format_f32(nudged(other)))[0] == 0
        assert g2("load-params", str(path), "--merge")[0] == 0
        assert value_of(g2, other.name) == nudged(other)
    finally:
        h2.stop()


def test_bad_file_sends_nothing(host, tmp_path, capsys, monkeypatch):
    g = InProcess(capsys, monkeypatch, host.port)
    d = settable("F32")[0]
    path = tmp_path / "part.json"
    P.write(path, P.from_values({d.name: nudged(d)}))
    text = path.read_text()
    crc = text.split('"crc32": "')[1][:10]
    path.write_text(text.replace(crc, "0x%08x" % (int(crc, 16) ^ 1)))
    before = g("diff")[1]
    rc, _, err = g("load-params", str(path))
    assert rc == 2 and "checksum mismatch" in err and "nothing sent" in err
    assert g("diff")[1] == before
    # nothing is sent: not even the port is opened
    r = InProcess(capsys, monkeypatch, "/nonexistent/tty")("load-params", str(path))
    assert r[0] == 2


def test_refused_value_stops(host, tmp_path, capsys, monkeypatch):
    """A value each check of the file passes but the firmware's design refuses (found on
    the gyro: a parameter at an end of its range that `set` answers REJECTED)."""
    g = InProcess(capsys, monkeypatch, host.port)
    assert g("drive", "off")[0] == 0
    found = None
    for d in TABLE.values():
        if not d.settable or d.type == "ENUM":
            continue
        for v in (d.min, d.max):
            text = P.format_f32(v) if d.type == "F32" else str(int(v))
            rc, _, err = g("set", d.name, text)
            if rc == 1 and "REJECTED" in err:
                found = (d, v)
                break
            assert g("defaults")[0] == 0
        if found:
            break
    if found is None:
        pytest.skip("no single value the design refuses in this table")
    d, v = found
    ok = settable("F32")[0] if settable("F32")[0] is not d else settable("F32")[1]
    path = tmp_path / "part.json"
    P.write(path, P.from_values([(ok.name, nudged(ok)), (d.name, v)]))
    flash = tmp_path / "flash.bin"
    before = flash.read_bytes() if flash.exists() else None
    rc, _, err = g("load-params", str(path))
    assert rc == 1, err
    assert "refused: err REJECTED" in err and d.name in err
    assert "`gyroctl load` restores flash" in err
    assert (flash.read_bytes() if flash.exists() else None) == before  # never saved


def test_calibration_tools_write_on_a_running_gyro(host, fw_pty_host, tmp_path, capsys,
                                                   monkeypatch):
    """gyro-tempcomp/gyro-demodcal --write (gyrotools.gyroctl_bridge) on a gyro whose drive
    runs: the values end in flash and the drive runs again. (It once set them live, then
    `save` was refused with the drive running: exit 2, the gyro on unsaved values.)"""
    from gyrotools import gyroctl_bridge
    monkeypatch.delenv("GYROCTL", raising=False)
    g = InProcess(capsys, monkeypatch, host.port)
    assert g("status")[1].splitlines()[-1] != "OFF"
    gyroctl_bridge.write_bias_coeffs(host.port, [0.5, 0.0125])
    assert value_of(g, "rate.bias_c0_dps") == P.f32(0.5)
    assert g("status")[1].splitlines()[-1] != "OFF"
    host.stop()
    h2 = Host(fw_pty_host, tmp_path / "flash.bin")
    try:
        g2 = InProcess(capsys, monkeypatch, h2.port)
        assert value_of(g2, "rate.bias_c0_dps") == P.f32(0.5)
        assert value_of(g2, "rate.bias_c1_dps_per_deg") == P.f32(0.0125)
        assert value_of(g2, "rate.bias_c3_dps_per_deg3") == 0.0
    finally:
        h2.stop()
