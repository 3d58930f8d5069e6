"""The firmware's self-calibration sweep as a frequency-response CSV for gyro-freqresp.

`sweep points` (firmware/app/app_cmds.c) prints the measured points of the latest sweep:

    - point K f_hz F amp_v A phase_deg P f_cmd_v2 C gain_v_per_v2 G stage S
    ok N points

f_hz is the force frequency (the NCO half-step, 2 half_step fs / 2^32; with the
half-frequency drive the voltages run at f_hz / 2), amp_v and phase_deg the mean drive
pickoff's amplitude and its phase against the force (force phase 0 during the steps;
arg Z - 90 deg in the phasor convention of firmware/gyro/gyro.h), f_cmd_v2 the force
command it had (Ks*V^2; the steps back off by halving it near the ADC limit), stage 1 the
first placement of the points and 2 the placement around the first fit.

The CSV is the one gyro-sim's sweep scenario writes (f_hz, amp, phase_deg; gyrotools/
freqresp.py): the amplitude is normalised by the excitation, amp = amp_v / f_cmd_v2 =
|H| in V per Ks*V^2 (gyro-sim's sweep holds the drive constant and writes volts; the fit
only needs one consistent unit, so f0 and Q come out alike). Extra columns follow
(amp_v, f_cmd_v2, stage) and '#' comment lines say what the points are.
"""

from __future__ import annotations

import dataclasses
import os
import time

CSV_COLUMNS = ("f_hz", "amp", "phase_deg", "amp_v", "f_cmd_v2", "stage")


class SweepError(Exception):
    pass


@dataclasses.dataclass
class Point:
    f_hz: float
    amp_v: float
    phase_deg: float
    f_cmd_v2: float
    gain_v_per_v2: float
    stage: int


def parse_point(line: str) -> Point:
    """One data line of `sweep points` (without its "- ")."""
    w = line.split()
    if len(w) < 2 or w[0] != "point" or len(w) % 2 != 0:
        raise SweepError(f"not a sweep point: {line!r}")
    kv = dict(zip(w[2::2], w[3::2]))
    try:
        return Point(float(kv["f_hz"]), float(kv["amp_v"]), float(kv["phase_deg"]),
                     float(kv["f_cmd_v2"]), float(kv["gain_v_per_v2"]), int(kv["stage"]))
    except (KeyError, ValueError) as e:
        raise SweepError(f"not a sweep point: {line!r} ({e})") from None


def points(link) -> list:
    """The latest sweep's points (CommandError with err STATE when there is none)."""
    r = link.command("sweep points", check=True)
    return [parse_point(d) for d in r.data]


def status_fields(link) -> dict:
    r = link.command("status", check=True)
    out = {}
    for d in r.data:
        k, _, v = d.partition(" ")
        out[k] = v
    return out


def run_and_wait(link, timeout_s: float, poll_s: float = 0.5, progress=None) -> dict:
    """`sweep`, then poll `status` until the sequencer is DONE or FAILED (wall clock
    timeout_s). Returns the last status; SweepError on FAILED or timeout."""
    link.command("sweep", check=True)
    t0 = time.monotonic()
    last = None
    while True:
        st = status_fields(link)
        state = st.get("selfcal", "?")
        if progress is not None and state != last:
            progress(f"sweep: {state} ({st.get('selfcal_s', '?')} s)")
            last = state
        if state == "DONE":
            return st
        if state == "FAILED":
            raise SweepError(f"sweep failed: {st.get('selfcal_why', 'no reason given')}")
        if time.monotonic() - t0 > timeout_s:
            raise SweepError(f"sweep not finished after {timeout_s:g} s (state {state})")
        time.sleep(poll_s)


def write_csv(pts, path, st=None) -> None:
    """The CSV gyro-freqresp reads; st (status fields) adds the firmware's own fit to the
    comment header. The file's folder is created if missing."""
    folder = os.path.dirname(os.path.abspath(str(path)))
    os.makedirs(folder, exist_ok=True)
    with open(path, "w", encoding="ascii", newline="\n") as f:
        f.write("# gyro self-calibration sweep (firmware `sweep points`): the settled steps "
                f"around the drive resonance, {len(pts)} points\n")
        f.write("# f_hz: force frequency (Hz); amp: drive pickoff amplitude per force command "
                "|Z|/f_cmd (V per Ks*V^2); phase_deg: drive pickoff against the force (deg)\n")
        f.write("# amp_v: drive pickoff amplitude (V); f_cmd_v2: force command (Ks*V^2); "
                "stage: 1 first placement, 2 placed again around the first fit\n")
        if st and "selfcal_f0_hz" in st:
            f.write(f"# firmware fit: f0_hz {st['selfcal_f0_hz']} q {st.get('selfcal_q', '?')} "
                    f"gain_v_per_v2 {st.get('selfcal_gain_v_per_v2', '?')}\n")
        f.write(",".join(CSV_COLUMNS) + "\n")
        for p in pts:
            f.write(f"{p.f_hz!r},{p.gain_v_per_v2!r},{p.phase_deg!r},{p.amp_v!r},"
                    f"{p.f_cmd_v2!r},{p.stage}\n")


def export(link, path, run=False, timeout_s=120.0, progress=None) -> int:
    """Write the latest sweep's points to path (after running a sweep when run).
    Returns the number of points."""
    st = run_and_wait(link, timeout_s, progress=progress) if run else status_fields(link)
    pts = points(link)  # CommandError (err STATE) when there are none
    if not pts:
        raise SweepError("the gyro returned no sweep points")
    write_csv(pts, path, st)
    return len(pts)
