"""The lot's engine: parts scheduled on Dask, each finished part kept, tables gathered.

DIR/stamp.json is the version stamp (gyro-sim's sha256, that of the Python making the
parts' values, the lot file's digest, --quick; the git commit for the record); every
part's row carries its id, and a DIR made by another version is refused, not mixed.
A finished part is DIR/parts/NNNNN/row.json (written atomically, with timing.json and
commands.json beside it); the same command run again skips those parts, so an
interrupted lot loses nothing. A part that times out or whose worker dies is retried
(Dask's retries); one that still fails is an error of the tool, not of the part: it has
no row, the run exits non-zero, and the same command runs it again.

Gathered: DIR/lot.parquet (one row per part, sorted, first column `part`; only values
that the versions, the lot file and the part index decide) and DIR/timings.parquet
(wall times, host, process: what the machine decides).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import logging
import os
import shutil
import subprocess
import sys
import time

import pandas as pd

from . import lotfile, lotjudge, lotpart
from .cli import write_json
from .errors import InputError

TOOLS = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STRING_COLUMNS = ("flow_error", "stamp", "fail_reason")


@dataclasses.dataclass
class Outcome:
    done_before: int = 0
    finished: int = 0
    failed: int = 0
    errors: dict = dataclasses.field(default_factory=dict)
    wall_s: float = 0.0
    sim_s: float = 0.0          # the scenarios' simulated time of the parts run (not the calibration's)
    workers: int = 0

    def record(self) -> dict:
        """What DIR/runs.json keeps of this run (host facts, for the throughput)."""
        return {"finished_unix_s": time.time(), "workers": self.workers, "parts_run": self.finished,
                "errors": len(self.errors), "wall_s": self.wall_s, "sim_s": self.sim_s,
                "part_hours_per_wall_hour": self.sim_s / self.wall_s if self.wall_s > 0 else None}


def _sha256(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def _commit() -> str:
    try:
        r = subprocess.run(["git", "-C", TOOLS, "describe", "--always", "--dirty", "--abbrev=12"],
                           capture_output=True, text=True, timeout=30)
        return r.stdout.strip() if r.returncode == 0 else "unknown"
    except (OSError, subprocess.TimeoutExpired):
        return "unknown"


def tools_digest() -> str:
    """The Python that makes a part's values: tools/calibrate and gyrotools, less the
    modules that only schedule, judge and report (judged again on every gather)."""
    h = hashlib.sha256()
    pkg = os.path.join(TOOLS, "gyrotools")
    files = [os.path.join(TOOLS, "calibrate")] + sorted(
        os.path.join(pkg, f) for f in os.listdir(pkg)
        if f.endswith(".py") and f not in ("lotrun.py", "lotjudge.py", "lotreport.py", "plotting.py"))
    for path in files:
        with open(path, "rb") as fh:
            h.update(os.path.basename(path).encode() + b"\0" + fh.read())
    return h.hexdigest()


def make_stamp(lot, gyro_sim: str, quick: bool) -> dict:
    """What decides a part's values (its id guards DIR), and the git commit for the record."""
    s = {"format": 1, "gyro_sim_sha256": _sha256(gyro_sim), "tools_sha256": tools_digest(),
         "lot_sha256": lot.digest, "quick": bool(quick)}
    s["id"] = hashlib.sha256(json.dumps(s, sort_keys=True).encode()).hexdigest()[:16]
    s["git"] = _commit()
    return s


def part_dir(out: str, k: int) -> str:
    return os.path.join(out, "parts", f"{k:05d}")


def _write_atomic(folder: str, name: str, obj):
    tmp = f".{name}.tmp"
    write_json(folder, tmp, obj)
    os.replace(os.path.join(folder, tmp), os.path.join(folder, name))


def claim(out: str, stamp: dict):
    """DIR/stamp.json written, or found equal; a DIR of another version is refused."""
    path = os.path.join(out, "stamp.json")
    if os.path.exists(path):
        try:
            with open(path, encoding="utf-8") as fh:
                old = json.load(fh)
        except (OSError, ValueError):
            raise InputError(f"{path}: unreadable stamp; delete {out} or use another --out") from None
        if old.get("id") != stamp["id"]:
            diff = [k for k in stamp if k not in ("id", "git") and old.get(k) != stamp[k]]
            raise InputError(f"{out}: holds parts of another version ({', '.join(diff) or 'format'} "
                             "differ): use another --out, or delete it")
    else:
        _write_atomic(out, "stamp.json", stamp)


def read_row(out: str, k: int):
    try:
        with open(os.path.join(part_dir(out, k), "row.json"), encoding="utf-8") as fh:
            return json.load(fh)
    except (OSError, ValueError):
        return None


def finished_parts(out: str, n: int, stamp_id: str) -> set:
    done = set()
    for k in range(n):
        row = read_row(out, k)
        if row is None:
            continue
        if row.get("stamp") != stamp_id:
            raise InputError(f"{part_dir(out, k)}/row.json: made by another version: use another "
                             "--out, or delete it")
        done.add(k)
    return done


def job(lot, k: int, out: str, gyro_sim: str, quick: bool, stamp_id: str) -> lotpart.PartJob:
    values, seed = lotfile.draw(lot, k)
    return lotpart.PartJob(k, values, dict(lot.base), seed, lot.calibrate, quick, lot.scenarios,
                           os.path.abspath(gyro_sim), TOOLS, os.path.abspath(part_dir(out, k)),
                           lot.timeout_s, stamp_id, lot.drive)


def _keep(out: str, k: int, res: dict):
    d = part_dir(out, k)
    os.makedirs(d, exist_ok=True)
    _write_atomic(d, "timing.json", res["timing"])
    _write_atomic(d, "commands.json", res["commands"])
    _write_atomic(d, "row.json", res["row"])   # last: its presence means "finished"


def _client(workers: int | None, scheduler: str | None, processes: bool = False):
    from distributed import Client, LocalCluster
    if scheduler:
        try:
            return Client(scheduler, timeout="20s"), None
        except (OSError, TimeoutError) as e:
            raise InputError(f"--scheduler {scheduler}: cannot connect ({e})") from None
    n = workers or os.cpu_count() or 1
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=processes,
                           dashboard_address=":0", silence_logs=logging.ERROR)  # any free port
    return Client(cluster), cluster


def _bar(total: int, initial: int, show: bool):
    from tqdm import tqdm
    return tqdm(total=total, initial=initial, unit="part", desc="lot", disable=not show,
                mininterval=1.0, file=sys.stderr, smoothing=0.1)


def _passes(row: dict, lot) -> bool:
    df = lotjudge.judge(pd.DataFrame([row]), lot.spec)
    return bool(df["pass"].iloc[0])


def schedule(lot, out: str, n: int, todo: list, opts) -> Outcome:
    """Runs the parts in todo on Dask; keeps each as it finishes."""
    from distributed import as_completed
    res = Outcome(done_before=n - len(todo))
    client, cluster = _client(opts.workers, opts.scheduler, getattr(opts, "processes", False))
    res.workers = len(client.scheduler_info().get("workers", {}))
    bar = _bar(n, res.done_before, opts.progress)
    t0 = time.monotonic()
    try:
        futures = {client.submit(lotpart.run_part, job(lot, k, out, opts.gyro_sim, opts.quick,
                                                       opts.stamp["id"]),
                                 key=f"lot-part-{k}-{opts.stamp['id']}", retries=opts.retries,
                                 pure=False): k for k in todo}
        for fut in as_completed(futures):
            k = futures[fut]
            try:
                r = fut.result()
            except Exception as e:  # noqa: BLE001  (any failure of the part's task)
                res.errors[k] = f"{type(e).__name__}: {e}"
            else:
                _keep(out, k, r)
                res.finished += 1
                res.sim_s += r["timing"].get("sim_s", 0.0)
                res.failed += 0 if _passes(r["row"], lot) else 1
            bar.update(1)
            bar.set_postfix(failed=res.failed, errors=len(res.errors), refresh=False)
    finally:
        bar.close()
        res.wall_s = time.monotonic() - t0
        client.close()
        if cluster is not None:
            cluster.close()
    return res


def _frame(records: list, strings=()) -> pd.DataFrame:
    df = pd.DataFrame.from_records(records)
    for c in df.columns:
        if c not in strings and c != "host":
            df[c] = pd.to_numeric(df[c], errors="coerce")
    return df


def gather(lot, out: str, n: int):
    """DIR/lot.parquet and DIR/timings.parquet from the finished parts below n."""
    rows, timings = [], []
    for k in range(n):
        row = read_row(out, k)
        if row is None:
            continue
        rows.append(row)
        try:
            with open(os.path.join(part_dir(out, k), "timing.json"), encoding="utf-8") as fh:
                timings.append(json.load(fh))
        except (OSError, ValueError):
            timings.append({"part": k})
    if not rows:
        return None
    df = _frame(rows, STRING_COLUMNS)
    df["part"] = df["part"].astype("int64")
    df["seed"] = df["seed"].astype("int64")
    df = lotjudge.judge(df.sort_values("part").reset_index(drop=True), lot.spec)
    df = df[["part"] + [c for c in df.columns if c != "part"]]
    df.to_parquet(os.path.join(out, "lot.parquet"), index=False)
    tf = _frame(timings).sort_values("part").reset_index(drop=True)
    tf.to_parquet(os.path.join(out, "timings.parquet"), index=False)
    return df


def log_run(out: str, res: Outcome):
    """Appends the run's record to DIR/runs.json."""
    path = os.path.join(out, "runs.json")
    try:
        with open(path, encoding="utf-8") as fh:
            runs = json.load(fh)
    except (OSError, ValueError):
        runs = []
    _write_atomic(out, "runs.json", runs + [res.record()])


def save_inputs(lot, out: str):
    """The lot and spec files as run, and the units of every column, beside the tables."""
    shutil.copyfile(lot.path, os.path.join(out, "lot.json"))
    shutil.copyfile(lot.spec_path, os.path.join(out, "spec.json"))
    write_json(out, "units.json", lot.units)
