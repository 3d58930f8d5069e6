"""boardcal: the firmware's lead-lag mirrored (its step response against the continuous
one), the model fitted on a known network recovers it, and a log that cannot carry a
model is refused with the reason."""

import numpy as np
import pytest
from scipy.signal import lfilter

from gyrotools import boardcal
from gyrotools.errors import InputError

STEP = boardcal.BOARD_STEP_S


def _lp(x, tau_s):
    a = 1.0 - np.exp(-STEP / tau_s)
    return lfilter([a], [1.0, -(1.0 - a)], x, zi=[x[0] * (1.0 - a)])[0]


def test_lead_lag_step_response_is_the_continuous_ones():
    n = int(600.0 / STEP)
    b = np.full(n, 20.0)
    b[10:] = 21.0
    tz, tp = (30.0, 50.0), (250.0, 50.0)
    y = boardcal.lead_lag(b, tz, tp, 25.0)
    t = (np.arange(n) - 9) * STEP  # the step taken on sample 10, as held over its step
    k = np.arange(10, n)
    want = 20.0 + 1.0 - (1.0 - 30.0 / 250.0) * np.exp(-t[k] / 250.0)
    np.testing.assert_allclose(y[k], want, atol=2e-4)
    assert y[0] == pytest.approx(20.0)  # starts in its steady state


def _network(seed=1):
    """A chamber's steps through a board node (180 s), the bias a cubic of the board
    through a known lead-lag, the reading a TMP117's held 1 s results."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 8000.0, STEP)
    amb = np.select([t < 2000, t < 4000, t < 6000], [25.0, 60.0, -10.0], 40.0)
    board = _lp(amb, 180.0)
    y = boardcal.lead_lag(board, (40.0, 20.0), (300.0, 20.0), 25.0)
    bias = 2.0 + 2.67 * (y - 25.0) + 0.003 * (y - 25.0) ** 2
    reading = np.round((board + rng.normal(0.0, 0.004, t.size)) / 2.0 ** -7) * 2.0 ** -7
    held = reading[(np.arange(t.size) // 10) * 10]
    return t, held, bias


@pytest.fixture(scope="module")
def fitted():
    t, held, bias = _network()
    return t, held, bias, boardcal.fit(t, held, bias, np.ones_like(t))


def test_fit_recovers_a_known_network(fitted):
    t, held, bias, m = fitted
    assert m.rms_dps < 0.01
    # the model reproduces the bias out of the fit's own rows' noise: every 1 s mean
    err = boardcal.model_bias(m, held) - bias
    assert np.sqrt(np.mean(err[t > 100] ** 2)) < 0.01
    v = boardcal.values(m)
    assert v["board.fuse"] == 1
    assert v["board.min_c"] < -9.0 and v["board.max_c"] > 59.0
    assert v["board.start_s"] == pytest.approx(max(boardcal.settle_s(m), boardcal.START_MIN_S))
    assert boardcal.TC_MIN_S <= min(m.tz_s + m.tp_s) and max(m.tz_s + m.tp_s) <= boardcal.TC_MAX_S


def test_nan_before_the_first_reading_is_none_yet():
    t, held, bias = _network()
    held = held.copy()
    held[:7] = np.nan
    grid, b = boardcal.held_grid(t, held)
    assert grid[0] == pytest.approx(t[7]) and np.all(np.isfinite(b))


@pytest.mark.parametrize("case, match", [
    ("no_readings", "no readings"),
    ("flat", "moved"),
    ("short", "s of readings"),
    ("not_at_rest", "at rest"),
    ("inf", "not finite"),
])
def test_a_log_without_a_model_is_refused(case, match):
    t, held, bias = _network()
    rest = np.ones_like(t)
    if case == "no_readings":
        held = np.full_like(held, np.nan)
    elif case == "flat":
        held = np.full_like(held, 25.0)
    elif case == "short":
        t, held, bias, rest = t[:300], held[:300], bias[:300], rest[:300]
    elif case == "inf":
        bias = bias.copy()
        bias[5000] = np.inf
    else:
        rest = np.zeros_like(t)
    with pytest.raises(InputError, match=match):
        boardcal.fit(t, held, bias, rest)


def test_parting_is_the_largest_disagreement(fitted):
    t, held, bias, m = fitted
    sf = np.full_like(t, 1.002)
    own = boardcal.parting_dps(t, held, sf * bias, m, sf)
    assert own < 0.1  # the largest 1 s miss of the fit itself, at a step of the chamber
    shifted = boardcal.parting_dps(t, held, sf * bias + 0.7, m, sf)
    assert shifted == pytest.approx(0.7, abs=0.1)
    v = boardcal.values(m, shifted)
    assert v["board.agree_dps"] == pytest.approx(boardcal.AGREE_FACTOR * shifted)
    assert boardcal.values(m, 0.0)["board.agree_dps"] == boardcal.AGREE_MIN_DPS


def test_settle_time_of_the_lead_lag():
    # one lag section: the error (1 - r) e^(-t / tp) falls below 1 % at tp ln(100 (1 - r))
    m = boardcal.BoardModel((50.0, 30.0), (200.0, 30.0), 25.0, np.zeros(4), 0.0, 0.0, 0.0)
    assert boardcal.settle_s(m) == pytest.approx(200.0 * np.log(100.0 * 0.75), abs=0.5)
    # a pole its zero nearly cancels (a residue under 1 %) does not count
    m2 = boardcal.BoardModel((50.0, 1243.0), (200.0, 1255.0), 25.0, np.zeros(4), 0.0, 0.0, 0.0)
    assert boardcal.settle_s(m2) < 1.2 * boardcal.settle_s(m)
