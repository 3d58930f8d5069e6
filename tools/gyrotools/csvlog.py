"""Reader and validator of the gyro's CSV logs.

Two producers write the same log format: the simulator (`gyro-sim`) and the UART tool
(`gyroctl log`). A log is one header row of column names, then one row per sample,
comma separated (spaces around fields are allowed; lines starting with '#' are comments):

    t_s, rate_true_dps, rate_dps, quad_dps, drive_amp, drive_phase_deg, p_deg,
    t_ambient_c, t_struct_c, t_board_c, u1_v, u2_v, adc_drive_v, adc_sense_v, flags

More columns may follow. Every loaded value must be finite, except in the columns of
NAN_COLUMNS, where "nan" means "no value at this row" (t_board_meas_c, board_c: the
board temperature sensor before its first conversion, absent or not answering). A column may
be asked for by its gyro-sim name or its telemetry name (drive_amp / drive_amp_v,
fields.ALIASES): the one the file has is read and returned under the name asked for. A
`gyroctl` log of real hardware has no truth columns (rate_true_dps, t_ambient_c,
t_struct_c). Every tool asks only for the columns it uses, and a missing one is reported
by name, so a gyroctl log works wherever the truth is not needed.

The frequency-sweep CSV (see freqresp) uses the same reader with no time column.

Only the requested columns are converted (numpy.loadtxt with usecols), so an unused
column (the hexadecimal `flags`, say) never matters. Returned data is a numpy structured
array of float64 fields named like the header.
"""

from __future__ import annotations

import dataclasses
import re
import warnings

import numpy as np

from .errors import InputError
from .fields import ALIASES

TIME_COLUMN = "t_s"
TRUTH_COLUMNS = ("rate_true_dps", "t_ambient_c", "t_struct_c")
# Columns where nan is a value ("no reading"), not a malformed row; inf still is refused.
NAN_COLUMNS = ("t_board_meas_c", "board_c")
LOG_COLUMNS = (
    "t_s", "rate_true_dps", "rate_dps", "quad_dps", "drive_amp", "drive_phase_deg",
    "p_deg", "t_ambient_c", "t_struct_c", "t_board_c", "u1_v", "u2_v", "adc_drive_v",
    "adc_sense_v", "flags",
)


@dataclasses.dataclass
class Log:
    """A loaded log: `data` holds the requested columns that were present."""

    path: str
    data: np.ndarray          # structured array, float64 fields
    header: tuple             # every column name in the file, in file order

    def __getitem__(self, name: str) -> np.ndarray:
        return self.data[name]

    def __contains__(self, name: str) -> bool:
        return name in self.data.dtype.names

    def __len__(self) -> int:
        return int(self.data.shape[0])


def _missing_message(path, name, purpose, header):
    msg = f"{path}: missing column '{name}'"
    if purpose:
        msg += f" (needed for {purpose})"
    msg += "; the log has: " + ", ".join(header)
    if name in TRUTH_COLUMNS:
        msg += " (a gyroctl log of real hardware has no truth columns)"
    return msg


def _lines_checked(fh, ncols, first_line, path):
    """Yield data lines, refusing any whose field count differs from the header's."""
    lineno = first_line
    for line in fh:
        lineno += 1
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        if stripped.count(",") + 1 != ncols:
            raise InputError(
                f"{path}:{lineno}: row has {stripped.count(',') + 1} fields, the header "
                f"has {ncols}")
        yield line


def _conversion_message(path, header_line, numpy_msg):
    """Turn numpy's 'could not convert string 'x' ... at row R' into a file line."""
    m = re.search(r"string '(.*)' to \w+ at row (\d+)", numpy_msg)
    if not m:
        return f"{path}: malformed data ({numpy_msg})"
    value, row = m.group(1), int(m.group(2))
    lineno, seen = 0, -1
    with open(path, "r", encoding="utf-8-sig") as fh:
        for lineno, line in enumerate(fh, start=1):
            s = line.strip()
            if lineno > header_line and s and not s.startswith("#"):
                seen += 1
                if seen == row:
                    break
    return f"{path}:{lineno}: malformed value '{value}' (not a number)"


def read_log(path, need=(), want=(), time_column=TIME_COLUMN, min_rows=2, purpose=""):
    """Load the columns `need` (required) and `want` (optional) of a CSV log.

    time_column (default t_s) is always required unless None, and must be strictly
    increasing. Every loaded value must be finite (nan allowed in NAN_COLUMNS).
    Raises InputError for an unreadable, empty, malformed, non-monotonic or too short
    (< min_rows data rows) file; `purpose` (e.g. "the Allan deviation") is quoted in the
    messages.
    """
    need = list(need)
    if time_column is not None and time_column not in need:
        need.insert(0, time_column)
    try:
        fh = open(path, "r", encoding="utf-8-sig", errors="strict")
    except OSError as e:
        raise InputError(f"{path}: cannot open ({e.strerror})") from None
    with fh:
        header_line = 0
        header = None
        try:
            for line in fh:
                header_line += 1
                s = line.strip()
                if s and not s.startswith("#"):
                    header = tuple(h.strip() for h in s.split(","))
                    break
        except UnicodeDecodeError:
            raise InputError(f"{path}: not a text CSV file") from None
        if header is None:
            raise InputError(f"{path}: empty file (no header row)")
        if any(h == "" for h in header) or len(set(header)) != len(header):
            raise InputError(f"{path}:{header_line}: header has empty or repeated names")
        if all(re.fullmatch(r"[-+0-9.eE]+|nan|inf", h) for h in header):
            raise InputError(f"{path}:{header_line}: first row is numbers, not a header")
        def present(n):
            return n if n in header else (ALIASES.get(n) if ALIASES.get(n) in header else None)

        for name in need:
            if present(name) is None:
                raise InputError(_missing_message(path, name, purpose, header))
        names = need + [w for w in want if present(w) is not None and w not in need]
        cols = [header.index(present(n)) for n in names]
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)  # "no data": checked below
                arr = np.loadtxt(
                    _lines_checked(fh, len(header), header_line, path),
                    delimiter=",", usecols=cols, dtype=np.float64, ndmin=2, comments="#")
        except InputError:
            raise
        except UnicodeDecodeError:
            raise InputError(f"{path}: not a text CSV file") from None
        except ValueError as e:
            raise InputError(_conversion_message(path, header_line, str(e))) from None
    nrows = arr.shape[0]
    if nrows == 0:
        raise InputError(f"{path}: log has a header but no data rows")
    data = np.empty(nrows, dtype=[(n, np.float64) for n in names])
    for i, n in enumerate(names):
        data[n] = arr[:, i]
    for n in names:
        bad = np.isinf(data[n]) if n in NAN_COLUMNS else ~np.isfinite(data[n])
        if bad.any():
            raise InputError(
                f"{path}: non-finite value in column '{n}' at data row {int(np.argmax(bad)) + 1}")
    if nrows < min_rows:
        what = f" for {purpose}" if purpose else ""
        raise InputError(f"{path}: log has {nrows} data rows; need at least {min_rows}{what}")
    if time_column is not None:
        dt = np.diff(data[time_column])
        if dt.size and (dt <= 0).any():
            k = int(np.argmax(dt <= 0))
            raise InputError(
                f"{path}: time column '{time_column}' is not increasing at data row {k + 2} "
                f"({data[time_column][k]:.9g} then {data[time_column][k + 1]:.9g})")
    return Log(path=str(path), data=data, header=header)


def sample_rate_hz(t_s, rel_tol=0.01, path="log"):
    """Sample rate of a uniformly sampled time column; InputError on gaps or jitter.

    Allan deviation and Welch PSD assume equally spaced samples: a dropped telemetry
    frame would fold a step into the statistics, so it is refused, not interpolated.
    """
    t_s = np.asarray(t_s, dtype=float)
    if t_s.size < 2:
        raise InputError(f"{path}: need at least 2 samples to know the sample rate")
    dt = np.diff(t_s)
    dt0 = float(np.median(dt))
    dev = np.abs(dt - dt0) > rel_tol * dt0
    if dev.any():
        k = int(np.argmax(dev))
        raise InputError(
            f"{path}: sampling is not uniform: step of {dt[k]:.6g} s at t = {t_s[k]:.6g} s "
            f"(typical {dt0:.6g} s); a gap-free log is needed")
    # The mean step is the better estimate once uniformity is established.
    return float((t_s.size - 1) / (t_s[-1] - t_s[0]))


def time_window(log, t_start=None, t_end=None, min_rows=2, time_column=TIME_COLUMN):
    """Rows with t_start <= t <= t_end (None: unbounded), as a new Log."""
    t = log[time_column]
    keep = np.ones(t.shape, dtype=bool)
    if t_start is not None:
        keep &= t >= t_start
    if t_end is not None:
        keep &= t <= t_end
    n = int(keep.sum())
    if n < min_rows:
        raise InputError(
            f"{log.path}: {n} rows between t = {t_start} and {t_end} s; need at least {min_rows}")
    return Log(path=log.path, data=log.data[keep], header=log.header)
