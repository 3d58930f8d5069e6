"""A 2-part lot of tiny start-ups through a real Dask LocalCluster: the same table with
1 and 2 worker processes; an interrupted lot (part 0 only) resumed without running part
0 again, into the same table (the default thread workers); another version's folder refused; two lots
compared. Needs gyro-sim: $GYRO_SIM (ctest python_lot sets it) or the host-release build;
skipped without one."""
import json
import os

import pandas as pd
import pytest

TOOLS = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SIM = os.environ.get("GYRO_SIM") or os.path.join(os.path.dirname(TOOLS),
                                                 "build/host-release/host_sim/gyro-sim")
pytestmark = pytest.mark.skipif(not os.access(SIM, os.X_OK), reason=f"no gyro-sim at {SIM}")

LOT = {"name": "tiny", "seed": 11, "parts": 2,
       "distributions": {
           "plant.f_drive_hz": {"dist": "normal", "mean": 1489.9, "sd": 10, "min": 1460, "max": 1520},
           "plant.q_drive": {"dist": "lognormal", "median": 33.33, "sigma_ln": 0.1}},
       "correlations": [{"a": "plant.f_drive_hz", "b": "plant.q_drive", "rho": 0.5}],
       "spec": "spec.json",
       "flow": {"calibrate": False, "scenarios": [{"name": "startup", "duration_s": 0.3}]},
       "timeout_s": 120}
SPEC = {"lines": [{"figure": "startup.lock_time_s", "max": 0.5, "unit": "s"},
                  {"figure": "startup.overshoot_pct", "max": 5, "unit": "%"},
                  {"figure": "cal.verified", "min": 1}]}


@pytest.fixture(scope="module")
def lotfile(tmp_path_factory):
    d = tmp_path_factory.mktemp("lotin")
    (d / "spec.json").write_text(json.dumps(SPEC))
    (d / "lot.json").write_text(json.dumps(LOT))
    return str(d / "lot.json")


def lot(run_script, lotfile, out, *extra):
    return run_script("lot", [lotfile, "--out", out, "--gyro-sim", SIM, "--no-progress", *extra])


def table(out):
    return pd.read_parquet(os.path.join(out, "lot.parquet"))


def test_same_table_with_1_and_2_workers_and_resumed(run_script, lotfile, tmp_path):
    one, two, resumed = (str(tmp_path / x) for x in ("one", "two", "resumed"))
    code, out, err = lot(run_script, lotfile, one, "--workers", "1", "--processes")
    assert code == 0, err
    assert "0 of 2 parts pass" not in out
    code, _, err = lot(run_script, lotfile, two, "--workers", "2", "--processes")
    assert code == 0, err
    a, b = table(one), table(two)
    assert list(a.columns[:1]) == ["part"] and list(a["part"]) == [0, 1]
    pd.testing.assert_frame_equal(a, b)
    assert a["pass.cal.verified"].isna().all()          # not measured: no calibration
    assert "not measured" in open(os.path.join(one, "report.md")).read().lower()

    # Interrupted after the first part, then the same command for the whole lot.
    code, _, err = lot(run_script, lotfile, resumed, "--workers", "2", "--parts", "1")
    assert code == 0, err
    row0 = os.path.join(resumed, "parts", "00000", "row.json")
    before = os.stat(row0).st_mtime_ns
    started = table_t(resumed)["started_unix_s"].tolist()
    code, out, err = lot(run_script, lotfile, resumed, "--workers", "2")
    assert code == 0, err
    assert "1 already finished, 1 to run" in out
    assert os.stat(row0).st_mtime_ns == before
    t = table_t(resumed)
    assert t["started_unix_s"].iloc[0] == started[0] and len(t) == 2
    pd.testing.assert_frame_equal(table(resumed), a)

    # Another version's folder is refused, nothing run.
    stamp = os.path.join(resumed, "stamp.json")
    s = json.load(open(stamp))
    s["id"], s["gyro_sim_sha256"] = "0" * 16, "0" * 64
    json.dump(s, open(stamp, "w"))
    code, _, err = lot(run_script, lotfile, resumed)
    assert code == 2 and "another version" in err and "gyro_sim_sha256" in err

    # Two lots compared: the same parts, no difference.
    code, out, err = run_script("lot", ["--out", one, "--compare", two])
    assert code == 0, err
    overall = [ln for ln in out.splitlines() if ln.startswith("| overall |")]
    assert overall and "| 0.0 % |" in overall[0]
    assert os.path.isfile(os.path.join(one, "compare.md"))


def table_t(out):
    return pd.read_parquet(os.path.join(out, "timings.parquet"))


def test_a_dead_worker_process_costs_nothing(run_script, lotfile, tmp_path):
    """A worker process killed (SIGKILL) while it runs a part: Dask's nanny starts a new
    one, the part runs again from nothing, and the table is the undisturbed lot's (but for
    the version stamp: the stand-in simulator is another file). The stand-in kills its
    parent, the worker process, on the first part run it sees, then is gyro-sim."""
    mark = tmp_path / "killed"
    sim = tmp_path / "gyro-sim"
    sim.write_text("#!/bin/sh\n"
                   "case \"$*\" in *--scenario*)\n"
                   f"  if mkdir '{mark}' 2>/dev/null; then kill -9 $PPID; sleep 30; exit 1; fi;;\n"
                   "esac\n"
                   f"exec '{SIM}' \"$@\"\n")
    sim.chmod(0o755)
    calm, hit = str(tmp_path / "calm"), str(tmp_path / "hit")
    code, _, err = lot(run_script, lotfile, calm, "--workers", "2", "--processes")
    assert code == 0, err
    code, _, err = run_script("lot", [lotfile, "--out", hit, "--gyro-sim", sim, "--no-progress",
                                      "--workers", "2", "--processes"])
    assert code == 0, err
    assert mark.is_dir()  # a worker was killed
    a, b = (table(x).drop(columns="stamp") for x in (calm, hit))
    pd.testing.assert_frame_equal(a, b)
