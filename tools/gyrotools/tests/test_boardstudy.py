"""boardstudy: the board sensor's model against its datasheet, the fusion's board -> P
model against a known thermal network, and the P path against thermcal's own fit."""

import dataclasses

import numpy as np
import pytest
from scipy import linalg

from gyrotools import boardstudy, compstudy, thermcal

S = boardstudy.TMP117


def test_sensor_constants_are_the_datasheets():
    # TI SNOSD82D: 1 LSB 7.8125 mdegC; 8 averages of 15.5 ms; +-3 LSB repeatability
    # single, about +-1 LSB with eight averages (here +-2 sigma: 0.53 LSB).
    assert S.lsb_c == 2.0 ** -7
    assert S.averages * S.conversion_s == pytest.approx(0.124)
    assert 2.0 * S.sigma_c / S.lsb_c == pytest.approx(1.06, abs=0.01)


def test_sensor_noise_rounding_and_rate_meet_the_spec():
    t = np.arange(0.0, 20000.0, 0.1)
    true = 25.3 + 0.0 * t
    r = boardstudy.sensor_reading(t, true, seed=7, part_seed=3)
    codes = r / S.lsb_c
    np.testing.assert_allclose(codes, np.round(codes), atol=1e-9)  # whole LSBs
    changes = np.flatnonzero(np.diff(r) != 0.0)
    # a new result at most once per conversion cycle, and on a cycle's grid
    assert np.min(np.diff(t[changes])) >= S.cycle_s - 0.1 - 1e-9
    conv = r[np.searchsorted(t, np.arange(5.0, 19990.0, S.cycle_s))]
    expect = np.hypot(S.sigma_c, S.lsb_c / np.sqrt(12.0))  # noise and rounding
    assert np.std(conv) == pytest.approx(expect, rel=0.05)
    off, slope = boardstudy.accuracy_error(S, 3)
    assert np.mean(conv) - 25.3 == pytest.approx(off + slope * 0.3, abs=5e-4)


def test_sensor_accuracy_error_stays_within_the_datasheets_limits():
    for seed in range(200):
        off, slope = boardstudy.accuracy_error(S, seed)
        assert abs(off) <= S.offset_max_c
        for tc in S.span_c + (25.0,):
            assert abs(off + slope * (tc - 25.0)) <= S.accuracy_max_c + 1e-12


def test_sensor_reads_a_ramp_half_a_cycle_late():
    t = np.arange(0.0, 1000.0, 0.01)  # rows fine against the cycle: their own grid's
    k = 0.02  # K/s                       # sampling of the held value averages out
    quiet = dataclasses.replace(S, sigma_single_lsb=0.0)
    r = boardstudy.sensor_reading(t, 25.0 + k * t, quiet, seed=1, part_seed=1)
    off, slope = boardstudy.accuracy_error(S, 1)
    read = (r - off + slope * 25.0) / (1.0 + slope)  # the accuracy error taken out
    m = t > 10.0
    lag = float(np.mean(25.0 + k * t[m] - read[m])) / k
    # held for half a cycle on average, read at the middle of its active conversion
    assert lag == pytest.approx(0.5 * S.cycle_s + 0.5 * S.averages * S.conversion_s, abs=0.012)


def _network(ambient, dt, tau=(400.0, 300.0, 180.0), g=(1 / 60, 0.0, 1 / 900),
             rise=(0.0, 1.5, 5.0)):
    """host_sim/plant/thermal.h's three nodes (structure, circuit, board), exact
    zero-order-hold steps of dt, from the steady state of ambient[0]."""
    g_sc, g_sb, g_cb = g
    lap = np.array([[g_sc + g_sb, -g_sc, -g_sb], [-g_sc, g_sc + g_cb, -g_cb],
                    [-g_sb, -g_cb, g_sb + g_cb]])
    lmat = np.diag(1.0 / np.array(tau)) + lap
    b = 1.0 / np.array(tau)
    h = np.array(rise) / np.array(tau)
    phi = linalg.expm(-lmat * dt)
    gam = np.linalg.solve(lmat, np.eye(3) - phi)
    x = np.linalg.solve(lmat, b * ambient[0] + h)
    out = np.empty((ambient.size, 3))
    for i, ta in enumerate(ambient):
        out[i] = x
        x = phi @ x + gam @ (b * ta + h)
    return out


def _p_of(ts, tc):
    # P reads the structure (and a little of the circuit), curved in temperature
    return 25.0 + 0.07 * (ts - 25.0) + 1e-4 * (ts - 25.0) ** 2 + 0.005 * (tc - 25.0)


def _steps(levels, dwell, dt):
    return np.repeat(np.asarray(levels, float), int(dwell / dt))


@pytest.mark.parametrize("g", [(1 / 60, 0.0, 1 / 900), (5e-5, 5e-5, 5e-5)])
def test_fusion_model_recovers_a_known_thermal_path(g):
    # Fitted on chamber plateaus, the board -> P model predicts P on a heat-gun transient
    # it never saw from the board sensor's reading, where the reading itself, scaled by
    # the static slope, is off by far more: the board lags and leads the structure.
    dt = 1.0
    amb = _steps([25, -40, -10, 10, 40, 60, 85], 2400.0, dt)
    t = np.arange(amb.size) * dt
    nodes = _network(amb, dt, g=g)
    p = _p_of(nodes[:, 0], nodes[:, 1])
    board = boardstudy.sensor_reading(t, nodes[:, 2], seed=2, part_seed=2)
    model = boardstudy.fit_board_model(t, board, p, np.ones_like(t, dtype=bool))
    assert model.rms < 2e-3
    t2 = np.arange(0.0, 2400.0, dt)
    amb2 = np.where(t2 < 120, 25.0, np.where(t2 < 720, 65.0 - 40.0 * np.exp(-(t2 - 120) / 90.0),
                                              25.0 + 40.0 * np.exp(-(t2 - 720) / 45.0)))
    n2 = _network(amb2, dt, g=g)
    p2 = _p_of(n2[:, 0], n2[:, 1])
    b2 = boardstudy.sensor_reading(t2, n2[:, 2], seed=3, part_seed=2)
    err = model(t2, b2) - p2
    static = np.polyfit(board, p, 3)
    err_static = np.polyval(static, b2) - p2
    assert np.max(np.abs(err)) < 0.01  # 0.1 K of structure
    assert np.max(np.abs(err_static)) > 10 * np.max(np.abs(err))


def test_fusion_model_of_the_bias_reads_the_circuit_p_does_not():
    # Loose coupling: the bias is mostly the circuit's (250 s), P reads the structure
    # (900 s). The board's model of the bias, fitted on the chamber run, follows the
    # bias through 40 K steps it never saw: exactly on the board node itself (two zeros
    # over two poles is the network's own transfer), within the sensor's noise on its
    # reading; P, mapped by its best static cubic, is off by over 20 deg/s.
    dt, g, tau = 1.0, (5e-5, 5e-5, 5e-5), (900.0, 250.0, 120.0)
    amb = _steps([25, -40, -10, 10, 40, 60, 85], 2400.0, dt)
    t = np.arange(amb.size) * dt
    nodes = _network(amb, dt, tau=tau, g=g)

    def bias(n):
        return 2.0 * (n[:, 1] - 25.0) + 0.7 * (n[:, 0] - 25.0)
    t2 = np.arange(0.0, 2400.0, dt)
    n2 = _network(25.0 + 40.0 * ((t2 > 120) & (t2 < 720)), dt, tau=tau, g=g)
    rest = np.ones_like(t, dtype=bool)
    exact = boardstudy.fit_board_model(t, nodes[:, 2], bias(nodes), rest)
    assert np.max(np.abs(exact(t2, n2[:, 2]) - bias(n2))) < 1e-6
    board = boardstudy.sensor_reading(t, nodes[:, 2], seed=2, part_seed=2)
    model = boardstudy.fit_board_model(t, board, bias(nodes), rest)
    err = model(t2, boardstudy.sensor_reading(t2, n2[:, 2], seed=3, part_seed=2)) - bias(n2)
    p_static = np.polyfit(_p_of(nodes[:, 0], nodes[:, 1]), bias(nodes), 3)
    err_p = np.polyval(p_static, _p_of(n2[:, 0], n2[:, 1])) - bias(n2)
    assert np.std(err) < 0.1 and np.max(np.abs(err)) < 0.5  # deg/s, of an 80 deg/s swing
    assert np.max(np.abs(err_p)) > 20.0


def test_fused_thermometer_keeps_p_fast_and_the_model_slow():
    t = np.arange(0.0, 6000.0, 0.1)
    rng = np.random.default_rng(4)
    truth = 25.0 + 0.5 * np.sin(2 * np.pi * t / 3000.0)
    drift = np.cumsum(rng.standard_normal(t.size)) * 2e-4  # P's slow wander
    p = truth + drift

    class Perfect:
        def __call__(self, t_s, board):
            return np.asarray(board)

    fused = boardstudy.fused_thermometer(t, p, truth, Perfect(), 20.0)
    late = t > 200.0
    # the slow wander is the model's business: taken out below the crossover
    assert np.std((fused - truth)[late]) < 0.2 * np.std(drift[late])
    # a step in P that the model does not make is P's at once, then fades with the
    # crossover's time constant as the model takes over
    step = p + 0.3 * (t >= 3000.0)
    f2 = boardstudy.fused_thermometer(t, step, truth, Perfect(), 20.0)
    i = np.searchsorted(t, 3000.0)
    keep = np.exp(-0.1 / 20.0)
    assert f2[i] - fused[i] == pytest.approx(0.3 * keep, abs=1e-9)
    assert f2[i + 1000] - fused[i + 1000] == pytest.approx(0.3 * keep ** 1001, abs=1e-9)
    # an endless crossover is P itself, less the disagreement held from the start
    assert np.ptp(boardstudy.fused_thermometer(t, p, truth, Perfect(), 1e9) - p) < 1e-6


def test_hand_over_after_power_on_has_no_step():
    t = np.arange(0.0, 3600.0, 0.1)
    out_p, out_f = np.full_like(t, 0.3), np.full_like(t, -0.1)
    out = boardstudy.handed_over(t, out_p, out_f)
    start, fade = boardstudy.FUSION_COLD_START_S, boardstudy.FUSION_FADE_S
    np.testing.assert_array_equal(out[t <= start], out_p[t <= start])
    np.testing.assert_array_equal(out[t >= start + fade], out_f[t >= start + fade])
    assert np.max(np.abs(np.diff(out))) <= 0.4 * 0.1 / fade + 1e-12


def _chamber_log(proto):
    amb_spec, rate_spec, dur = thermcal._plateau_profiles(proto.cal_plateaus_c, proto.dwell_s)

    def steps(spec, t):
        edges = np.cumsum([d for d, _ in spec])
        vals = np.array([v for _, v in spec])
        return vals[np.minimum(np.searchsorted(edges, t, side="right"), vals.size - 1)]
    t = np.arange(0.0, dur, 0.1)
    nodes = _network(steps(amb_spec, t), 0.1)
    p = _p_of(nodes[:, 0], nodes[:, 1])
    r = steps(rate_spec, t)
    bias = 35.0 * (p - 25.0) + 0.3 * (nodes[:, 1] - nodes[:, 0])
    return {"t_s": t, "p_f_deg": p, "t_struct_c": nodes[:, 0], "t_board_c": nodes[:, 2],
            "rate_true_dps": r, "rate_unc_dps": (r + bias) / (1 + 1e-5 * (p - 25.0)),
            "rate_valid": np.ones_like(t)}


def test_p_path_reproduces_thermcals_fit():
    proto = thermcal.FULL
    log = _chamber_log(proto)
    v_ref, _, figs_ref = thermcal.fit(log, proto.cal_plateaus_c, proto.dwell_s,
                                      comp_tau_s=proto.comp_tau_s,
                                      comp_stages=proto.comp_stages,
                                      comp_fast_tau_s=proto.comp_fast_tau_s)
    lv = boardstudy.view(log, log["p_f_deg"], boardstudy.linearised(log, {}))
    v, figs = boardstudy.fit(lv, proto)
    assert v == v_ref
    assert figs["fit_rms_1s_dps"] == figs_ref["fit_rms_1s_dps"]
    out = boardstudy.compensated(lv, v, proto)["rate_dps"]
    np.testing.assert_array_equal(out, compstudy.compensate(log, v, proto.comp_tau_s,
                                                            proto.comp_stages))
    # the linearisation is the firmware's: L(u) = u + u^2 (c2 + u c3)
    lin = boardstudy.linearised(log, {"rate.lin_c2_per_dps": 1e-6, "rate.lin_c3_per_dps2": 0})
    u = log["rate_unc_dps"]
    np.testing.assert_allclose(lin, u + 1e-6 * u * u)


def test_cli_refuses_a_case_without_its_logs(run_script, tmp_path):
    code, _, err = run_script("board_thermometer_study", ["--case", "x", "--out", tmp_path])
    assert code == 2 and "NAME:WORK" in err
    code, _, err = run_script("board_thermometer_study",
                              ["--case", f"x:{tmp_path}", "--out", tmp_path])
    assert code == 2 and "thermal.csv" in err
