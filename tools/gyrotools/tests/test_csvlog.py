"""csvlog: the reader accepts both producers' logs and refuses bad ones with a clear,
located message."""
import numpy as np
import pytest
import synth

from gyrotools import csvlog
from gyrotools.errors import InputError

HEADER = ("t_s, rate_true_dps, rate_dps, quad_dps, drive_amp, drive_phase_deg, p_deg, "
          "t_ambient_c, t_struct_c, t_board_c, u1_v, u2_v, adc_drive_v, adc_sense_v, flags")


def write(tmp_path, text, name="log.csv"):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


def rows(n, t0=0.0, dt=0.01):
    return "".join(f"{t0 + i * dt:.6f},0,{i * 0.5},0,1,-99,0.1,25,25,25,1,1,0,0,0x{i:04x}\n"
                   for i in range(n))


def test_reads_requested_columns_of_a_sim_log(tmp_path):
    p = write(tmp_path, "# gyro-sim v1\n" + HEADER + "\n" + rows(5))
    log = csvlog.read_log(p, need=["rate_dps"], want=["p_deg", "not_there"])
    assert log.data.dtype.names == ("t_s", "rate_dps", "p_deg")
    np.testing.assert_allclose(log["rate_dps"], [0, 0.5, 1.0, 1.5, 2.0])
    np.testing.assert_allclose(log["t_s"], [0, 0.01, 0.02, 0.03, 0.04])
    assert len(log) == 5 and "p_deg" in log and "not_there" not in log
    assert log.header[-1] == "flags"


def test_gyroctl_log_without_truth_is_fine_when_truth_is_not_needed(tmp_path):
    p = synth.write_log(tmp_path / "g.csv", {"t_s": np.arange(10) * 0.01,
                                             "rate_dps": np.ones(10)},
                        drop=("rate_true_dps", "t_ambient_c", "t_struct_c"))
    log = csvlog.read_log(p, need=["rate_dps"], want=["rate_true_dps"])
    assert "rate_true_dps" not in log
    with pytest.raises(InputError, match=r"missing column 'rate_true_dps' \(needed for "
                                         r"segments\).*no truth columns"):
        csvlog.read_log(p, need=["rate_true_dps"], purpose="segments")


def test_extra_columns_after_the_standard_ones_are_allowed(tmp_path):
    p = write(tmp_path, HEADER + ", extra_v\n" + "".join(
        r.rstrip("\n") + ",7\n" for r in rows(3).splitlines(True)))
    log = csvlog.read_log(p, need=["extra_v"])
    np.testing.assert_allclose(log["extra_v"], 7)


@pytest.mark.parametrize("text, msg", [
    ("", "empty file"),
    ("# only a comment\n\n", "empty file"),
    (HEADER + "\n", "no data rows"),
    ("1,2,3\n4,5,6\n", "numbers, not a header"),
    ("t_s,rate_dps,rate_dps\n0,1,2\n", "repeated"),
    (HEADER + "\n" + rows(2) + "0.5,0,1,2\n", r":4: row has 4 fields, the header has 15"),
    (HEADER + "\n" + rows(2) + "0.5,0,abc,0,1,-99,0.1,25,25,25,1,1,0,0,0\n",
     r":4: malformed value .abc."),
    (HEADER + "\n" + rows(2) + "0.5,0,nan,0,1,-99,0.1,25,25,25,1,1,0,0,0\n",
     "non-finite value in column 'rate_dps' at data row 3"),
    (HEADER + "\n" + rows(3) + rows(2, t0=0.01),
     r"not increasing at data row 4 \(0.02 then 0.01\)"),
])
def test_bad_files_are_refused_with_a_located_message(tmp_path, text, msg):
    p = write(tmp_path, text)
    with pytest.raises(InputError, match=msg):
        csvlog.read_log(p, need=["rate_dps"])


def test_board_sensor_column_may_hold_nan_where_it_has_no_reading(tmp_path):
    text = HEADER + ", t_board_meas_c\n" + "".join(
        f"{i * 0.5:.6f},0,0,0,1,-99,0.1,25,25,25,1,1,0,0,0x0,{v}\n"
        for i, v in enumerate(("nan", "25.0390625", "25.0468750", "nan")))
    log = csvlog.read_log(write(tmp_path, text), need=["t_board_meas_c"])
    np.testing.assert_array_equal(np.isnan(log["t_board_meas_c"]), [True, False, False, True])
    assert log["t_board_meas_c"][1] == 25.0390625
    bad = write(tmp_path, HEADER + ", t_board_meas_c\n" + rows(2).replace("\n", ",inf\n"),
                "inf.csv")
    with pytest.raises(InputError, match="non-finite value in column 't_board_meas_c'"):
        csvlog.read_log(bad, need=["t_board_meas_c"])
    with pytest.raises(InputError, match="non-finite value in column 'p_deg'"):
        csvlog.read_log(write(tmp_path, text.replace(",0.1,", ",nan,"), "p.csv"), need=["p_deg"])


def test_windows_line_ends_and_byte_order_mark(tmp_path):
    p = tmp_path / "win.csv"
    p.write_bytes(("\ufeff" + HEADER + "\r\n" + rows(4).replace("\n", "\r\n"))
                  .encode("utf-8"))
    log = csvlog.read_log(str(p), need=["rate_dps"])
    np.testing.assert_allclose(log["rate_dps"], [0, 0.5, 1.0, 1.5])


def test_too_short_and_unreadable(tmp_path):
    p = write(tmp_path, HEADER + "\n" + rows(3))
    with pytest.raises(InputError, match="3 data rows; need at least 10 for the test"):
        csvlog.read_log(p, need=["rate_dps"], min_rows=10, purpose="the test")
    with pytest.raises(InputError, match="cannot open"):
        csvlog.read_log(str(tmp_path / "nope.csv"))
    b = tmp_path / "bin.csv"
    b.write_bytes(b"\xff\xfe\x00\x01garbage")
    with pytest.raises(InputError, match="not a text CSV"):
        csvlog.read_log(str(b))


def test_sample_rate_and_gap_detection():
    t = np.arange(1000) * 0.002
    assert csvlog.sample_rate_hz(t) == pytest.approx(500.0, rel=1e-12)
    gap = np.delete(t, 500)
    with pytest.raises(InputError, match=r"not uniform: step of 0.004 s at t = 0.998"):
        csvlog.sample_rate_hz(gap)


def test_time_window(tmp_path):
    p = write(tmp_path, HEADER + "\n" + rows(100))
    log = csvlog.read_log(p, need=["rate_dps"])
    w = csvlog.time_window(log, 0.2, 0.5)
    assert w["t_s"][0] == pytest.approx(0.2) and w["t_s"][-1] == pytest.approx(0.5)
    with pytest.raises(InputError, match="0 rows between"):
        csvlog.time_window(log, 5.0, None)


def test_telemetry_and_simulator_names_alike(tmp_path):
    """A gyroctl log says drive_amp_v, gyro-sim says drive_amp: either name reads either
    file, returned under the name asked for; a name neither has is still refused."""
    from gyrotools import csvlog as cl
    from gyrotools.errors import InputError as IE
    for col in ("drive_amp", "drive_amp_v"):
        p = tmp_path / f"{col}.csv"
        p.write_text(f"t_s,{col}\n0,0.5\n0.01,0.25\n")
        for asked in ("drive_amp", "drive_amp_v"):
            log = cl.read_log(str(p), need=[asked])
            assert list(log[asked]) == [0.5, 0.25]
        with pytest.raises(IE):
            cl.read_log(str(p), need=["drive_amp_x"])
