"""calport: the flow's scenarios as a bench plays them (moves of the rate table and the
chamber, the commands, a cold start), the bench's setpoints as the log's truth, and the
refusals of what a bench cannot play."""
import math

import numpy as np
import pytest

from gyrotools import calport, thermcal
from gyrotools.calport import Move, PortError


def test_table_steps_are_moves_at_their_edges():
    prof = {"kind": "steps", "edge_s": 0.1, "steps": [[2.0, 0], [3.0, 50], [1.0, -50]]}
    v0, moves = calport.profile_moves(prof, "rate", 0.0, 0.5)
    assert v0 == 0.0
    assert moves == [Move(2.0, "rate", 50.0, 0.1), Move(5.0, "rate", -50.0, 0.1)]


def test_a_ramp_is_one_move_over_its_span_and_a_constant_none():
    v0, moves = calport.profile_moves({"kind": "ramp", "value": 25.0, "slope_per_s": 2.0 / 60,
                                       "t_start_s": 120.0, "t_end_s": 1320.0}, "ambient", 0, 60)
    assert v0 == 25.0 and moves == [Move(120.0, "ambient", pytest.approx(65.0), 1200.0)]
    assert calport.profile_moves({"kind": "const", "value": 30}, "ambient", 25.0, 60) == (30.0, [])
    assert calport.profile_moves(None, "rate", 0.0, 0.1) == (0.0, [])


def test_heat_cool_follows_the_curve_within_a_step():
    base, hot, t0, heat, th, tc, _ = thermcal.TRANSIENT
    prof = {"kind": "heat_cool", "value": base, "hot_value": hot, "t_start_s": t0,
            "heat_s": heat, "tau_heat_s": th, "tau_cool_s": tc}
    v0, moves = calport.profile_moves(prof, "ambient", 25.0, 60.0)
    assert v0 == base and all(m.edge_s == calport.HEAT_COOL_STEP_S for m in moves)
    truth = calport.Truth(v0)
    for m in moves:
        truth.move(m.t_s, m.to, m.edge_s)
    t = np.array([t0 + 60.0, t0 + heat, t0 + heat + 90.0])
    exact = [base + (hot - base) * (1 - math.exp(-60.0 / th)),
             base + (hot - base) * (1 - math.exp(-heat / th))]
    exact.append(base + (exact[1] - base) * math.exp(-90.0 / tc))
    # Linear moves towards the curve 5 s ahead: off by at most the curve's change over
    # one step, 40 K (1 - exp(-5/90)) = 2.2 K at the heating's start; 0.5 K here.
    assert truth.at(t) == pytest.approx(exact, abs=0.6)


def test_what_a_bench_cannot_play_is_refused():
    with pytest.raises(PortError, match="kind 'sine'"):
        calport.profile_moves({"kind": "sine", "value": 0, "amp": 1}, "rate", 0, 0.1)
    with pytest.raises(PortError, match="q_drive"):
        calport.timeline({"duration_s": 1, "plant": {"q_drive": 100}})
    with pytest.raises(PortError, match="selfcal"):
        calport.timeline({"duration_s": 1, "selfcal": True})
    tl = calport.timeline({"duration_s": 10, "plant": {"cold_start": True}, "csv_rate_hz": 1000,
                           "commands": [[5, "status"], [1, "selftest"]]})
    assert tl.cold_start and tl.rate_hz == calport.MAX_RATE_HZ
    assert tl.commands == [(1.0, "selftest"), (5.0, "status")]


def test_truth_is_the_played_moves_from_where_each_began():
    t = calport.Truth(0.0)
    t.move(1.0, 50.0, 0.5)
    t.move(1.25, -10.0, 1.0)  # turned back half way up: from 25
    got = t.at(np.array([0.5, 1.0, 1.25, 1.75, 2.25, 3.0]))
    assert got == pytest.approx([0.0, 0.0, 25.0, 7.5, -10.0, -10.0])


def test_the_manual_bench_asks_the_operator_and_counts_from_enter():
    said, asked = [], []
    b = calport.ManualBench(ask=lambda p: asked.append(p) or "", say=said.append)
    assert b.move("rate", -30.0, 0.1, 12.5) == 12.5
    assert b.soak(70.0, 13.0) == 0.0
    b.cold(25.0, 14.0)
    assert len(asked) == 3
    assert "rate table to -30 deg/s" in said[0] and "chamber to 70 degC" in said[1]
    assert "switch the part off" in said[2]
    with pytest.raises(PortError, match="bench 'robot'"):
        calport.bench_for("robot", None)
