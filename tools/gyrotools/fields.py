"""Names and units of the logged quantities, shared by the tools' axes and the field
dictionary docs/fields.md (tools/gen_fields_doc.py).

Two producers name the same quantities (tools/gyrotools/csvlog.py): gyro-sim's CSV and
`gyroctl log`, whose columns are the firmware's telemetry field names
(firmware/app/app_tlm_fields.h). They differ in one name only, the drive amplitude
(gyro-sim `drive_amp`, telemetry `drive_amp_v`); ALIASES lets every tool accept both.
Units follow the name's suffix, which the firmware's table keeps by rule
(_dps, _v, _deg, _v2); the simulator's truth columns add _c, _m, _s.
"""

from __future__ import annotations

import numpy as np

ALIASES = {"drive_amp": "drive_amp_v", "drive_amp_v": "drive_amp"}

# The RATE_INVALID_* reasons by bit (firmware/gyro/rate_valid.h; the column rate_invalid
# and `status`); tests/test_fields.py holds them to the header.
RATE_INVALID = ("MODE", "SELFTEST", "SETTLING", "CLIP", "SENSE_RANGE", "OVER_RANGE", "PHASE",
                "THERMO_RANGE", "THERMO_SLEW", "THERMO_SETTLE", "CONT_SELFTEST", "TRACKING",
                "UNCALIBRATED", "QUAD_NULL", "SENSE_FR", "TUNE", "BOARD_TEMP")


def invalid_time_s(t_s, rate_invalid):
    """Seconds of a log with each RATE_INVALID_* reason set (a row stands for the time to
    the next; reasons overlap, so the sum may exceed the invalid time): {name: s}, the
    reasons never set left out."""
    t = np.asarray(t_s, dtype=float)
    bits = np.asarray(rate_invalid).astype(np.int64)
    if t.size < 2:
        return {}
    dt = np.diff(t, append=t[-1] + float(np.median(np.diff(t))))
    out = {}
    for k, name in enumerate(RATE_INVALID):
        sec = float(np.sum(dt[(bits >> k) & 1 == 1]))
        if sec > 0.0:
            out[name] = sec
    return out


# Units that the suffix rule cannot give.
UNIT_BY_NAME = {"drive_amp": "V", "flags": "-", "mode": "-", "fault": "-", "tick": "-",
                "rate_valid": "-", "rate_invalid": "-", "clock_ppm": "ppm"}
SUFFIX_UNITS = (("_dps", "deg/s"), ("_v2", "V^2"), ("_deg", "deg"), ("_v", "V"),
                ("_c", "degC"), ("_m", "m"), ("_s", "s"), ("_hz", "Hz"))

# Meaning of gyro-sim's CSV columns (host_sim/gyro_sim/sim_out.c writes the header);
# the columns that are firmware outputs carry the firmware's meaning.
CSV_MEANING = {
    "t_s": "simulated time since power-on",
    "rate_true_dps": "input rate applied to the plant (truth)",
    "rate_dps": "rate output, compensated and filtered (firmware)",
    "quad_dps": "quadrature, as an equivalent rate (firmware)",
    "quad_true_dps": "the plant's quadrature as an equivalent rate, beside the firmware's "
                     "quad_dps: the stiffness coupling (k_q = 2 wc quad_dps and its drift, "
                     "both following the structure temperature, plus the quadrature-nulling "
                     "electrodes' k_yx) over 2 wc at the drive frequency (truth)",
    "fb_u1_v": "sense feedback pair electrode U3 (fb_mode 3), mean voltage over the sample as "
               "the part sees it: the DAC's spare channel plus any series voltage, without "
               "the electrode noise; 0 on a part without the pair (truth)",
    "fb_u2_v": "sense feedback pair electrode U4, as fb_u1_v, from the second converter's "
               "channel HAL_DAC_SENSE_FB_U2 (truth)",
    "quadnull_v": "quadrature-nulling voltage, signed: sign(m1 - m2) sqrt|m1 - m2| of the two "
                  "sets' mean squares, so the coupling is c quadnull_v |quadnull_v|; +V1 "
                  "with set 1 alone driven (adds to a positive quadrature), -V2 with set 2 "
                  "alone (cancels it); 0 on a part without nulling electrodes (truth)",
    "tune_v": "sense tuning electrodes' mean voltage (the softening goes as its square); 0 on "
              "a part without them (truth)",
    "drive_amp": "demodulated drive pickoff amplitude (firmware; telemetry drive_amp_v)",
    "drive_phase_deg": "phase of the drive pickoff phasor (firmware)",
    "p_deg": "the temperature signal: force phase P (fixed drive), or its equivalent from the "
             "tracked frequency, p_init - (2Q/f0)(f - f_cal) (tracking drive) (firmware)",
    "t_ambient_c": "ambient temperature (truth)",
    "t_struct_c": "sensor structure temperature (truth)",
    "t_board_c": "the board's thermal node, where its temperature sensor sits (truth)",
    "t_board_meas_c": "the board temperature sensor's latest result as the firmware reads it "
                      "(the TMP117's code times 7.8125 mdegC: t_board_c 62 ms before the 1 s "
                      "conversion ended, with the sensor's accuracy error and noise, "
                      "plant.board_sensor_*); nan before its first conversion, without a sensor "
                      "and while it does not answer",
    "board_c": "the board temperature sensor's latest result as the firmware took it "
               "(hal_board_temp.h; t_board_meas_c a background pass later); nan before its "
               "first (firmware)",
    "u1_v": "drive electrode 1 voltage written this tick (firmware)",
    "u2_v": "drive electrode 2 voltage written this tick (firmware)",
    "adc_drive_v": "drive pickoff at the ADC input (truth)",
    "adc_sense_v": "sense pickoff at the ADC input (truth)",
    "flags": "GYRO_FLAG_* bits of the tick (firmware), below",
    "mode": "supervisor mode code (firmware), below",
    "t_circuit_c": "pickoff circuit temperature (truth)",
    "rate_unc_dps": "rate before temperature compensation (firmware)",
    "p_f_deg": "P low-passed, what the compensation uses (firmware)",
    "drive_amp_true_m": "true drive displacement amplitude (truth)",
    "f_cmd_v2": "drive force command (firmware)",
    "rate_valid": "1 when the rate output can be trusted, 0 when not (firmware, output integrity)",
    "rate_out_v": "voltage commanded on the analog rate output in the same tick: the rate "
                  "times rate.out_v_per_dps when valid, rate.fault_out_v when not (firmware)",
    "f_drive_hz": "drive (NCO) frequency, from its integer step: the tracked resonance with "
                  "drive.track 1 (firmware; telemetry f_drive_hz, a float)",
    "clock_ppm": "the sample clock's error (+: fast), plant.clock_* (truth)",
    "f_drive_true_hz": "f_drive_hz in true time: the NCO's frequency on the sample clock as "
                       "it really runs, f_drive_hz (1 + clock_ppm 1e-6) (truth)",
    "aout_v": "the analog rate output's voltage as a meter reads it: the DAC's level of "
              "rate_out_v with the converter's INL, gain and offset (truth)",
    "rate_invalid": "RATE_INVALID_* reasons of the tick's verdict, 0 when the rate is valid "
                    "(firmware/gyro/rate_valid.h; `status` names them)",
}


def unit_of(name: str) -> str:
    """Unit of a column or field name ('' when unknown)."""
    if name in UNIT_BY_NAME:
        return UNIT_BY_NAME[name]
    for suffix, unit in SUFFIX_UNITS:
        if name.endswith(suffix):
            return unit
    return ""


def axis_label(name: str, scale: float = 1.0) -> str:
    """'name [unit]' for an axis; dimensionless counts and codes get no unit."""
    unit = unit_of(name)
    if unit == "m" and scale == 1e6:
        unit = "um"
    return f"{name} [{unit}]" if unit and unit != "-" else name
