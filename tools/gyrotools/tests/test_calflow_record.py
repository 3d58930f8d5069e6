"""The calibration record (calflow.record): cal.ref_tune_v is the mode tuning's voltage at
its own reference, the firmware's (firmware/gyro/sense_tune.h), so that another tuning
makes the calibration stale; untuned it is 0. The sense configuration the flow calibrates
(calflow.sense_config) is the firmware settings it names, and the record carries it."""
import math

import pytest

from gyrotools import calflow
from gyrotools.errors import InputError

BASE = {"drive.freq_hz": 1489.86, "drive.phase_set_deg": 0.0, "drive.track": 0}


def tuned(mode, split_hz=0.0, v_max=10.0):
    v = dict(BASE)
    v.update({"sense.tune": mode, "sense.tune_split_hz": split_hz, "sense.tune_v_max_v": v_max,
              "sense.cal_s0_hz": 1600.0, "sense.cal_tune_ref_hz": 1489.86,
              "sense.cal_tune_ke_per_s2_per_v2": 2.4e5})
    return v


def volts(s0, target, ke):
    return math.sqrt(((2 * math.pi * s0) ** 2 - (2 * math.pi * target) ** 2) / ke)


def test_untuned_records_zero():
    assert calflow.record(dict(BASE), ["x=1"])["cal.ref_tune_v"] == 0.0
    assert calflow.record(tuned(0), ["x=1"])["cal.ref_tune_v"] == 0.0


def test_matched_and_split_record_the_firmware_law():
    assert math.isclose(calflow.record(tuned(1), [])["cal.ref_tune_v"],
                        volts(1600.0, 1489.86, 2.4e5), rel_tol=1e-12)
    assert math.isclose(calflow.record(tuned(2, 20.0), [])["cal.ref_tune_v"],
                        volts(1600.0, 1509.86, 2.4e5), rel_tol=1e-12)


def test_a_target_out_of_reach_records_what_the_firmware_applies():
    assert calflow.record(tuned(1, v_max=5.0), [])["cal.ref_tune_v"] == 5.0
    below = tuned(1)
    below["sense.cal_s0_hz"] = 1480.0
    assert calflow.record(below, [])["cal.ref_tune_v"] == 0.0


def test_fr_phase_wraps():
    assert calflow.wrap_deg(190.0) == -170.0
    assert calflow.wrap_deg(-180.0) == -180.0


def test_the_record_names_its_sense_configuration():
    """cal.ref_sense_mode and cal.ref_quad_null are the configuration the stages ran in:
    the firmware holds a calibration of another one stale (gyro_design.c)."""
    r = calflow.record(dict(BASE), [])
    assert r["cal.ref_sense_mode"] == 0 and r["cal.ref_quad_null"] == 0
    v = dict(BASE)
    v.update({"sense.mode": 1, "quad.null": 1})
    r = calflow.record(v, [])
    assert r["cal.ref_sense_mode"] == 1 and r["cal.ref_quad_null"] == 1


def test_the_sense_configuration_is_the_firmware_settings_it_names():
    sc = calflow.sense_config
    assert sc() == {}
    assert sc("fr") == {"sense.mode": 1, "sense.fb_scheme": 0, "sense.cal": 1}
    assert sc("fr", "dcac", quad_null=True) == {"sense.mode": 1, "sense.fb_scheme": 1,
                                                "quad.null": 1, "sense.cal": 1}
    assert sc("fr", tune="matched") == {"sense.mode": 1, "sense.fb_scheme": 0,
                                        "sense.tune": 1, "sense.cal": 1}
    # a split tunes open loop too; nulling alone needs no sense model
    assert sc(tune="split") == {"sense.tune": 2, "sense.cal": 1}
    assert sc(quad_null=True) == {"quad.null": 1}


@pytest.mark.parametrize("args", [("open", "half"), ("open", None, False, "matched"),
                                  ("closed",), ("fr", "ac"), ("fr", None, False, "on")])
def test_a_sense_configuration_the_firmware_refuses_is_refused(args):
    with pytest.raises(InputError):
        calflow.sense_config(*args)


def test_the_record_of_a_force_rebalance_calibration_names_it():
    v = calflow.record(dict(BASE, **calflow.sense_config("fr", quad_null=True)), [])
    assert v["cal.ref_sense_mode"] == 1 and v["cal.ref_quad_null"] == 1


def _status(detune, match):
    return f"ok status\r\n- tune_detune_hz {detune}\r\n- tune_match {match}\r\n"


def test_the_lost_match_monitors_zero_is_its_reading_on_the_tuned_part():
    assert calflow.disc_zero(_status(-1.94, 1), {}, "cmd") == pytest.approx(-1.94)
    # read against the zero the run already had
    assert calflow.disc_zero(_status(0.25, 1), {"sense.tune_disc_zero_hz": -1.5},
                             "cmd") == pytest.approx(-1.25)


@pytest.mark.parametrize("reply", [_status(-1.0, 0), "ok status\r\n", _status(-12.0, 2)])
def test_no_reading_or_one_beyond_a_tuned_part_fails_the_stage(reply):
    with pytest.raises(calflow.FlowError):
        calflow.disc_zero(reply, {}, "cmd")
