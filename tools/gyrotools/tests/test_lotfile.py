"""Lot files: the checks refuse bad input with one line and write nothing; the draw of
part k depends on the lot seed and k alone; the copula correlates; figures a run lacks
are not measured, never a pass."""
import json
import math
import os
import stat

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from gyrotools import lotfile, lotjudge, lotpart
from gyrotools.errors import InputError

PARAMS_TEXT = """# plant parameters (plant.KEY)
plant.f_drive_hz                               1489.9       [10, 1e+06] Hz  drive resonance at temp_ref_k
plant.q_drive                                  33.33        [0.5, 1e+06]   drive resonance quality factor
plant.quad_dps                                 1500         [-100000, 100000] deg/s  quadrature
plant.preset                                   thesis       [thesis, ideal]   part preset
# firmware parameters (firmware.NAME)
firmware.drive.track                           0            [0, 1] -  0 fixed frequency
"""
TABLE = lotfile.parse_param_list(PARAMS_TEXT)
SPEC = {"lines": [{"figure": "startup.lock_time_s", "max": 0.5, "unit": "s"},
                  {"figure": "cal.verified", "min": 1}]}


def good_lot():
    return {"name": "t", "seed": 3, "parts": 4, "base": {"plant.preset": "thesis"},
            "distributions": {
                "plant.f_drive_hz": {"dist": "normal", "mean": 1489.9, "sd": 15, "min": 1450, "max": 1530},
                "plant.q_drive": {"dist": "lognormal", "median": 33.33, "sigma_ln": 0.1},
                "plant.quad_dps": {"dist": "uniform", "min": 1000, "max": 2000}},
            "correlations": [{"a": "plant.f_drive_hz", "b": "plant.q_drive", "rho": 0.8}],
            "spec": "spec.json",
            "flow": {"calibrate": False, "scenarios": [{"name": "startup", "duration_s": 0.3}]}}


def write(tmp_path, lot, spec=SPEC, raw=None):
    (tmp_path / "spec.json").write_text(json.dumps(spec))
    p = tmp_path / "lot.json"
    p.write_text(raw if raw is not None else json.dumps(lot))
    return str(p)


def test_table_parsed():
    assert TABLE["plant.f_drive_hz"].lo == 10 and TABLE["plant.f_drive_hz"].unit == "Hz"
    assert TABLE["plant.preset"].choices == ("thesis", "ideal")


def test_draw_depends_on_seed_and_index_only(tmp_path):
    lot = lotfile.load(write(tmp_path, good_lot()), TABLE)
    later = lotfile.draw(lot, 7)
    for k in range(7):
        lotfile.draw(lot, k)
    assert lotfile.draw(lot, 7) == later
    assert lotfile.draw(lot, 6) != later
    other = lotfile.load(write(tmp_path, {**good_lot(), "seed": 4}), TABLE)
    assert lotfile.draw(other, 7) != later


def test_draw_bounds_marginals_and_correlation(tmp_path):
    lot = lotfile.load(write(tmp_path, good_lot()), TABLE)
    draws = pd.DataFrame([lotfile.draw(lot, k)[0] for k in range(600)])
    assert draws["plant.f_drive_hz"].between(1450, 1530).all()
    assert draws["plant.quad_dps"].between(1000, 2000).all()
    assert abs(np.median(draws["plant.q_drive"]) / 33.33 - 1) < 0.02
    assert abs(draws["plant.f_drive_hz"].std() / 15 - 1) < 0.15   # truncated at 2.7 sd
    rho = stats.spearmanr(draws["plant.f_drive_hz"], draws["plant.q_drive"]).statistic
    assert abs(rho - 6 / math.pi * math.asin(0.4)) < 0.07        # Gaussian copula, rho 0.8
    assert stats.kstest((draws["plant.quad_dps"] - 1000) / 1000, "uniform").pvalue > 0.01


def test_digest_ignores_part_count_and_spec(tmp_path):
    a = lotfile.load(write(tmp_path, good_lot()), TABLE)
    b = lotfile.load(write(tmp_path, {**good_lot(), "parts": 99, "timeout_s": 5}), TABLE)
    c = lotfile.load(write(tmp_path, {**good_lot(), "seed": 5}), TABLE)
    assert a.digest == b.digest != c.digest


def _mut(path, value):
    """good_lot() with the key at path (a tuple) set to value (None: deleted)."""
    lot = good_lot()
    obj = lot
    for k in path[:-1]:
        obj = obj[k]
    if value is None:
        del obj[path[-1]]
    else:
        obj[path[-1]] = value
    return lot


BAD = [
    (_mut(("seed",), "3"), "seed"), (_mut(("seed",), True), "seed"), (_mut(("seed",), 1.5), "integer"),
    (_mut(("seed",), -1), "below"), (_mut(("parts",), 0), "parts"), (_mut(("parts",), 10**12), "above"),
    (_mut(("name",), None), "missing key 'name'"), (_mut(("colour",), "red"), "unknown key 'colour'"),
    (_mut(("distributions",), {}), "non-empty"),
    (_mut(("distributions", "plant.f_drive_hz", "sd"), -1), "sd"),
    (_mut(("distributions", "plant.f_drive_hz", "sd"), None), "missing key 'sd'"),
    (_mut(("distributions", "plant.f_drive_hz", "dist"), "cauchy"), "dist"),
    (_mut(("distributions", "plant.f_drive_hz", "min"), 1600), "min 1600 must be below max"),
    (_mut(("distributions", "plant.f_drive_hz", "min"), 1), "below 10"),
    (_mut(("distributions", "plant.f_drive_hz", "mean"), 1e300), "no probability"),
    (_mut(("distributions", "plant.f_drive_hz", "spread"), 2), "unknown key 'spread'"),
    (_mut(("distributions", "plant.q_drive", "sigma_ln"), 0), "sigma_ln"),
    (_mut(("distributions", "plant.quad_dps", "max"), 500), "below max"),
    (_mut(("distributions", "plant.nonsense"), {"dist": "uniform", "min": 0, "max": 1}), "not a gyro-sim parameter"),
    (_mut(("distributions", "firmware.drive.track"), {"dist": "uniform", "min": 0, "max": 1}), "not a plant"),
    (_mut(("distributions", "plant.preset"), {"dist": "uniform", "min": 0, "max": 1}), "takes names"),
    (_mut(("base", "plant.preset"), "shiny"), "not one of"),
    (_mut(("base", "plant.f_drive_hz"), 1500), "both fixed"),
    (_mut(("base", "plant.q_drive"), 1e7), "above"),
    (_mut(("correlations",), [{"a": "plant.f_drive_hz", "b": "plant.nope", "rho": 0.5}]), "not one of"),
    (_mut(("correlations",), [{"a": "plant.f_drive_hz", "b": "plant.q_drive", "rho": 1.5}]), "above 1"),
    (_mut(("correlations",), [{"a": "plant.q_drive", "b": "plant.q_drive", "rho": 0.5}]), "same parameter"),
    (_mut(("correlations",), [{"a": "plant.f_drive_hz", "b": "plant.q_drive", "rho": 0.9},
                              {"a": "plant.q_drive", "b": "plant.quad_dps", "rho": 0.9},
                              {"a": "plant.f_drive_hz", "b": "plant.quad_dps", "rho": -0.9}]), "positive definite"),
    (_mut(("correlations",), [{"a": "plant.f_drive_hz", "b": "plant.q_drive", "rho": 0.2},
                              {"a": "plant.q_drive", "b": "plant.f_drive_hz", "rho": 0.2}]), "given twice"),
    (_mut(("spec",), "missing.json"), "cannot read the spec"),
    (_mut(("spec",), 3), "spec must be"),
    (_mut(("flow", "calibrate"), "yes"), "true or false"),
    (_mut(("flow", "drive"), "pll"), "one of auto, fixed, tracking"),
    (_mut(("flow", "scenarios"), []), "nothing to run"),
    (_mut(("flow", "scenarios"), [{"name": "nope_not_there"}]), "no such file"),
    (_mut(("flow", "scenarios"), [{"name": "Startup!"}]), "identifier"),
    (_mut(("flow", "scenarios"), [{"name": "startup"}, {"name": "startup"}]), "given twice"),
    (_mut(("flow", "scenarios"), [{"name": "startup", "duration_s": -1}]), "duration_s"),
    (_mut(("flow", "scenarios"), [{"name": "startup", "duration_s": "long"}]), "not a number"),
]


@pytest.mark.parametrize("lot,hint", BAD)
def test_bad_lot_refused_with_one_line(tmp_path, lot, hint):
    with pytest.raises(InputError) as e:
        lotfile.load(write(tmp_path, lot), TABLE)
    assert hint in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("raw,hint", [
    ("{", "not valid JSON"), ("[1, 2]", "must be a JSON object"), ("", "not valid JSON"),
    ('{"seed": NaN}', "not a JSON number"), ('{"seed": Infinity}', "not a JSON number"),
    ('{"seed": 1e999}', "not finite"), ('{"seed": 1, "seed": 2}', "given twice"),
    ("\xff\xfe", "not valid JSON"),
])
def test_malformed_json_refused(tmp_path, raw, hint):
    lot = good_lot()
    if "1e999" in raw:
        raw = json.dumps(lot).replace('"mean": 1489.9', '"mean": 1e999')
    with pytest.raises(InputError) as e:
        lotfile.load(write(tmp_path, lot, raw=raw), TABLE)
    assert hint in str(e.value)


def test_missing_lot_file(tmp_path):
    with pytest.raises(InputError, match="cannot read the lot file"):
        lotfile.load(str(tmp_path / "none.json"), TABLE)


@pytest.mark.parametrize("spec,hint", [
    ({"lines": []}, "non-empty"), ({"lines": [{"figure": "startup.lock_time_s"}]}, "min, max"),
    ({"lines": [{"figure": "stratup.lock_time_s", "max": 1}]}, "SOURCE one of"),
    ({"lines": [{"figure": "lock_time_s", "max": 1}]}, "SOURCE.NAME"),
    ({"lines": [{"figure": "startup.x", "min": 2, "max": 1}]}, "below max"),
    ({"lines": [{"figure": "startup.x", "max": 1}, {"figure": "startup.x", "min": 0}]}, "two lines"),
    ({"lines": [{"figure": "startup.x", "max": 1, "limit": 3}]}, "unknown key 'limit'"),
    ({"lines": [{"figure": "startup.x", "max": "1"}]}, "not a number"),
])
def test_bad_spec_refused(tmp_path, spec, hint):
    with pytest.raises(InputError) as e:
        lotfile.load(write(tmp_path, good_lot(), spec=spec), TABLE)
    assert hint in str(e.value)


def test_cli_refuses_bad_lot_and_writes_nothing(tmp_path, run_script):
    sim = tmp_path / "gyro-sim"
    sim.write_text("#!/bin/sh\ncat <<'EOF'\n" + PARAMS_TEXT + "EOF\n")
    sim.chmod(sim.stat().st_mode | stat.S_IXUSR)
    path = write(tmp_path, _mut(("distributions", "plant.q_drive", "median"), -3))
    out = tmp_path / "lot_out"
    code, _, err = run_script("lot", [path, "--out", out, "--gyro-sim", sim, "--no-progress"])
    assert code == 2 and "lot: error:" in err and "median" in err and len(err.splitlines()) == 1
    assert not os.path.exists(out)


def test_cal_figures_defensive():
    assert all(math.isnan(v) for v in lotpart.cal_figures({}).values())
    plateaus = [{"bias_dps": -0.07}, {"bias_dps": 0.03}]
    rep = {"selfcal": {"s": 8.8}, "verify": {"rate": {"nonlinearity_fs": 2e-4, "scale_factor_ppm": None},
                                             "thermal_plateaus": {"plateaus": plateaus}}}
    f = lotpart.cal_figures(rep)
    assert f["cal.selfcal_s"] == 8.8 and f["cal.temp_bias_max_dps"] == 0.07
    assert math.isclose(f["cal.nonlinearity_pct_fs"], 0.02) and math.isnan(f["cal.sf_ppm"])


def test_not_measured_is_neither_pass_nor_fail():
    spec = (lotfile.SpecLine("startup.lock_time_s", None, 0.5, "s"), lotfile.SpecLine("cal.verified", 1, None))
    df = pd.DataFrame({"part": [0, 1, 2], "startup.lock_time_s": [0.1, 0.7, np.nan],
                       "flow_error": ["", "", "startup: exit 1"]})
    j = lotjudge.judge(df, spec)
    assert list(j["pass.startup.lock_time_s"].astype(object)) == [True, False, pd.NA]
    assert j["pass.cal.verified"].isna().all()
    assert list(j["pass"]) == [True, False, False]
    assert "startup.lock_time_s 0.7 > 0.5" in j.at[1, "fail_reason"]
    assert j.at[2, "fail_reason"] == "startup: exit 1"


def test_part_over_its_time_is_ended_with_its_children(tmp_path):
    sim = tmp_path / "slow-sim"
    pidfile = tmp_path / "child.pid"
    sim.write_text(f"#!/bin/sh\nsleep 30 &\necho $! > {pidfile}\nwait\n")
    sim.chmod(sim.stat().st_mode | stat.S_IXUSR)
    sc = lotfile.Scenario("startup", str(sim), 0.3, None, False)
    job = lotpart.PartJob(0, {"plant.q_drive": 30.0}, {}, 1, False, False, (sc,), str(sim), "",
                          str(tmp_path / "p0"), 0.5, "x")
    with pytest.raises(lotpart.PartTimeout, match="still running"):
        lotpart.run_part(job)
    psutil = pytest.importorskip("psutil")
    try:
        child = psutil.Process(int(pidfile.read_text()))
        child.wait(timeout=2) if child.status() != psutil.STATUS_ZOMBIE else None
    except psutil.NoSuchProcess:
        pass                                    # gone, as it should be


def test_yield_intervals():
    from gyrotools import lotreport
    p, lo, hi = lotreport.ci(0, 16)
    assert p == 0 and lo == 0 and abs(hi - 0.2059) < 1e-3          # Clopper-Pearson
    d, lo, hi = lotreport.newcombe(56, 70, 48, 80)                  # Newcombe (1998), method 10
    assert abs(d - 0.2) < 1e-12 and abs(lo - 0.0524) < 1e-3 and abs(hi - 0.3339) < 1e-3


def test_part_ended_from_outside_keeps_no_row(tmp_path):
    sim = tmp_path / "killed-sim"
    sim.write_text("#!/bin/sh\nkill -INT $$\n")
    sim.chmod(sim.stat().st_mode | stat.S_IXUSR)
    sc = lotfile.Scenario("startup", str(sim), 0.3, None, False)
    job = lotpart.PartJob(0, {}, {}, 1, False, False, (sc,), str(sim), "", str(tmp_path / "p0"), 10, "x")
    with pytest.raises(lotpart.PartInterrupted, match="ended from outside"):
        lotpart.run_part(job)


def test_calibration_date_is_a_host_fact(tmp_path):
    p = tmp_path / "calibration.json"
    p.write_text(json.dumps({"params": [{"name": "rate.scale_dps", "value": 139.2},
                                        {"name": "cal.date", "value": 20261124}]}))
    row, host = {}, {}
    lotpart._written(str(p), row, host)
    assert row == {"calw.rate.scale_dps": 139.2} and host == {"calw.cal.date": 20261124.0}


FLAKY_SIM = """#!/bin/sh
# --list-params: the table; a run: ended from outside the first time, figures after.
if [ "$1" = "--list-params" ]; then cat <<'EOF2'
PARAMS
EOF2
exit 0; fi
if [ ! -e "MARK" ]; then touch "MARK"; kill -TERM $$; fi
while [ $# -gt 0 ]; do [ "$1" = "--json" ] && out="$2"; shift; done
echo '{"figures": {"lock_time_s": 0.02}}' > "$out"
"""


@pytest.mark.parametrize("retries,code", [("2", 0), ("0", 1)])
def test_part_retried_through_dask(tmp_path, run_script, retries, code):
    sim = tmp_path / "flaky-sim"
    sim.write_text(FLAKY_SIM.replace("PARAMS", PARAMS_TEXT).replace("MARK", str(tmp_path / "mark")))
    sim.chmod(sim.stat().st_mode | stat.S_IXUSR)
    lot = good_lot()
    lot["parts"] = 1
    out = tmp_path / "lot_out"
    code_, stdout, err = run_script("lot", [write(tmp_path, lot), "--out", out, "--gyro-sim", sim,
                                            "--no-progress", "--workers", "1", "--retries", retries])
    assert code_ == code, err
    row = out / "parts" / "00000" / "row.json"
    if code == 0:
        assert json.loads(row.read_text())["startup.lock_time_s"] == 0.02
    else:
        assert not row.exists() and "ended from outside" in err and "run the same command again" in err


def test_drive_mode_read(tmp_path):
    """flow.drive: the calibration flow's drive mode (tools/calibrate --drive), part of the
    lot's digest; auto by default; only with a calibration."""
    lot = good_lot()
    lot["flow"]["calibrate"] = True
    plain = lotfile.load(write(tmp_path, lot), TABLE)
    assert plain.drive == "auto"
    lot["flow"]["drive"] = "tracking"
    got = lotfile.load(write(tmp_path, lot), TABLE)
    assert got.drive == "tracking" and got.digest != plain.digest
    lot["flow"]["calibrate"] = False
    with pytest.raises(InputError, match="only with calibrate true"):
        lotfile.load(write(tmp_path, lot), TABLE)


def test_each_part_is_its_own_board():
    """A part's converters (plant.board_seed) follow from its seed, the same in its
    calibration and its scenarios; another part is another board; a lot's own board_seed
    wins; the calibration gets the plant keys only."""
    from gyrotools import lotpart

    def job(seed, base):
        return lotpart.PartJob(0, {"plant.q_drive": 40.0}, base, seed, True, True, (), "sim",
                               "tools", "dir", 10.0, "stamp")
    a = lotpart.part_settings(job(123, {"firmware.drive.amp_set_v": 0.3}))
    assert a["plant.board_seed"] == "123" and a["firmware.drive.amp_set_v"] == 0.3
    cal = lotpart.part_settings(job(123, {"firmware.drive.amp_set_v": 0.3}), plant_only=True)
    assert cal == {"plant.board_seed": "123", "plant.q_drive": 40.0}
    assert lotpart.part_settings(job(124, {}))["plant.board_seed"] == "124"
    assert lotpart.part_settings(job(123, {"plant.board_seed": 7}))["plant.board_seed"] == 7
