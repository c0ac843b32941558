"""Cycles from an embedding and the periodic LME stroke."""
import numpy as np
import pytest

import pointatlas
from pointatlas.errors import InputError
from pointatlas_studies.metaboly_stroke import PeriodicLME, find_cycles


def loop_embedding(times, starts, arc=False):
    idx = np.searchsorted(starts, times, side="right") - 1
    ph = (times - starts[idx]) / np.diff(starts)[idx]
    a = 2 * np.pi * ph
    if arc:
        return np.column_stack([-np.cos(a), 0.02 * np.sin(3 * a)]), ph
    return np.column_stack([-np.cos(a), np.sin(a)]), ph


@pytest.mark.parametrize("arc", [False, True])
@pytest.mark.parametrize("durations, tol", [([10.0] * 4, 0.01), ([9.0, 11.0, 10.0, 12.5], 0.05)])
def test_cycles_and_phases(arc, durations, tol):
    """Shuffled frames of four cycles; with unequal cycles a recovered cycle (cut where y₁
    rises through its median, a quarter into each true cycle) spans two true cycles of
    different durations, so its frames' phases can only match to a few per cent."""
    rng = np.random.default_rng(3)
    starts = np.concatenate([[0.0], np.cumsum(durations)])
    t = rng.permutation(np.sort(rng.uniform(0, starts[-1], 300)))     # shuffled frames
    Y, ph = loop_embedding(t, starts, arc)
    Y += rng.normal(0, 0.01, Y.shape)
    c = find_cycles(Y, t)
    assert c.n_cycles == 3 and c.loop is (not arc)
    # the cycles start where y₁ rises through its median, about a quarter into each true cycle
    true_starts = starts[:4] + 0.25 * np.diff(starts)[:4]
    np.testing.assert_allclose(c.starts, true_starts, atol=0.2)
    assert c.period == pytest.approx(np.mean(np.diff(true_starts)), rel=0.01)
    inside = (t > c.starts[0]) & (t < c.starts[-1])           # the end cycles are partial
    d = np.angle(np.exp(2j * np.pi * (c.phase - ph)[inside]))  # phase differences, circular
    d -= np.angle(np.mean(np.exp(1j * d)))                     # less the common offset
    assert np.abs(np.angle(np.exp(1j * d))).max() / (2 * np.pi) < tol


def test_less_than_a_cycle_is_refused():
    t = np.linspace(0, 8, 50)
    Y, _ = loop_embedding(t, np.array([0.0, 10.0]))
    with pytest.raises(InputError, match="fewer than one full cycle in 50 frames"):
        find_cycles(Y, t)


def test_periodic_lme_fits_a_smooth_periodic_function():
    lme = PeriodicLME(pointatlas.load_plugin("approximants", "lme")(gamma=0.8), n_bins=40)
    rng = np.random.default_rng(0)
    ph = rng.uniform(0, 1, 400)
    f = np.column_stack([np.sin(2 * np.pi * ph), np.cos(4 * np.pi * ph)])
    lme.fit(ph, f)
    q = np.linspace(0, 1, 101)
    X, dX = lme(q)
    assert np.abs(X[:, 0] - np.sin(2 * np.pi * q)).max() < 2e-2
    assert np.abs(dX[:, 0] - 2 * np.pi * np.cos(2 * np.pi * q)).max() < 0.2
    X0, _ = lme(np.array([0.0, 1.0]))
    np.testing.assert_allclose(X0[0], X0[1], atol=1e-12)          # periodic


def test_empty_phase_bins_are_refused():
    lme = PeriodicLME(pointatlas.load_plugin("approximants", "lme")(gamma=0.8), n_bins=40)
    ph = np.random.default_rng(0).uniform(0, 0.5, 100)
    with pytest.raises(InputError, match="no frames near phase"):
        lme.fit(ph, ph[:, None])
