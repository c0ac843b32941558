"""The 2-D tabulated reduced Lagrangian: bicubic Hermite exactness on polynomials, O(h⁴)
convergence, the numba integrator against the general one, bounded energy, and the refusals
(leaving the sampled region, Newton failing, a start outside)."""
import numpy as np
import pytest

from pointatlas.errors import InputError
from pointatlas_reduction.reduced_lagrangian import ReducedTerms
from pointatlas_reduction.tabulated_2d import Table2D, integrate_table_2d
from pointatlas_reduction.variational_integrator import integrate


def lagrangian(V, dV, M, dM, region=None):
    """(terms, terms_batch) of Ṽ, ∂Ṽ (2, m), M̃ (2, 2, m), ∂M̃ (2, 2, 2, m) given as functions
    of (q1, q2); ``region(q1, q2)`` flags the sampled points (all by default)."""
    def batch(Q):
        x, y = Q[:, 0], Q[:, 1]
        shape = (2, 2, len(Q))
        Mq = np.broadcast_to(np.asarray(M(x, y), float), shape)
        dMq = np.broadcast_to(np.asarray(dM(x, y), float), (2,) + shape)
        valid = np.ones(len(Q), bool) if region is None else region(x, y)
        return (valid, np.moveaxis(Mq, -1, 0), np.moveaxis(dMq, -1, 0),
                np.broadcast_to(V(x, y), len(Q)) + 0.0,
                -np.moveaxis(np.broadcast_to(np.asarray(dV(x, y), float), (2, len(Q))), -1, 0))

    def terms(q):
        ok, M_, dM_, V_, F_ = batch(np.asarray(q, float).reshape(1, 2))
        nan = np.nan if not ok[0] else 0.0
        return ReducedTerms(M_[0] + nan, dM_[0], float(V_[0]), F_[0])
    return terms, batch


Z = np.zeros
# bicubic, with ∂₁f at most quadratic in q2 and ∂₂f in q1: the FD cross derivative is exact
POLY = lagrangian(
    lambda x, y: x ** 3 - 2 * x ** 2 * y ** 2 + y ** 3 + x * y,
    lambda x, y: [3 * x ** 2 - 4 * x * y ** 2 + y, -4 * x ** 2 * y + 3 * y ** 2 + x],
    lambda x, y: [[2 + x ** 2 + y ** 2, 0.3 * x * y], [0.3 * x * y, 3 + x ** 2 * y ** 2]],
    lambda x, y: [[[2 * x, 2 * y], [0.3 * y, 0.3 * x]],
                  [[0.3 * y, 0.3 * x], [2 * x * y ** 2, 2 * x ** 2 * y]]],
    region=lambda x, y: x < 0.7)
SMOOTH = lagrangian(
    lambda x, y: np.cos(x) + 0.5 * y ** 2, lambda x, y: [-np.sin(x), y],
    lambda x, y: [[1 + 0.3 * np.sin(y), 0.1 + Z(x.shape)], [0.1 + Z(x.shape), 1 + 0.2 * x ** 2]],
    lambda x, y: [[[Z(x.shape), 0.3 * np.cos(y)], [Z(x.shape), Z(x.shape)]],
                  [[Z(x.shape), Z(x.shape)], [0.4 * x, Z(x.shape)]]])
# a well: 1 − cos q1 + q2² with a configuration-dependent, coupled mass
WELL = lagrangian(
    lambda x, y: 1 - np.cos(x) + y ** 2, lambda x, y: [np.sin(x), 2 * y],
    lambda x, y: [[1 + 0.3 * np.sin(y), 0.1 * x * y], [0.1 * x * y, 1 + 0.2 * x ** 2]],
    lambda x, y: [[[Z(x.shape), 0.3 * np.cos(y)], [0.1 * y, 0.1 * x]],
                  [[0.1 * y, 0.1 * x], [0.4 * x, Z(x.shape)]]])


def test_bicubic_polynomials_are_reproduced_exactly():
    terms, _ = POLY
    tab = Table2D(terms, [-1.0, -0.5], [1.0, 1.5], (11, 9))      # invalid beyond q1 = 0.6
    assert not tab.valid.all() and tab.usable[:8].all() and not tab.usable[8:].any()
    assert tab.table_error < 1e-12
    rng = np.random.default_rng(0)
    Q = rng.uniform([-1.0, -0.5], [0.6, 1.5], (200, 2))
    for q in Q:
        t, e = tab.terms(q), terms(q)
        np.testing.assert_allclose(t.mass, e.mass, rtol=0, atol=1e-12)
        np.testing.assert_allclose(t.mass_derivative, e.mass_derivative, rtol=0, atol=1e-11)
        assert t.potential == pytest.approx(e.potential, abs=1e-12)
        np.testing.assert_allclose(t.force, e.force, rtol=0, atol=1e-11)
    assert not tab.contains([0.7, 0.0]) and np.isnan(tab.terms([0.7, 0.0]).potential)


def test_the_table_converges_as_h4_and_the_loop_matches_the_batch():
    terms, batch = SMOOTH
    err = [Table2D.from_batch(batch, [-2.0, -2.0], [2.0, 2.0], (n, n)).table_error
           for n in (17, 33)]
    assert err[0] / err[1] > 8 and err[1] < 1e-6
    a = Table2D(terms, [-2.0, -1.0], [1.0, 2.0], (13, 9))
    b = Table2D.from_batch(batch, [-2.0, -1.0], [1.0, 2.0], (13, 9))
    np.testing.assert_allclose(a.coefficients, b.coefficients, rtol=1e-13, atol=1e-13)


def test_the_tabulated_path_matches_the_general_one():
    terms, batch = WELL
    tab = Table2D.from_batch(batch, [-2.0, -2.0], [2.0, 2.0], (129, 129))
    assert tab.table_error < 1e-8
    dt, n = 0.02, 300
    t, Q, P, E, done = integrate_table_2d(tab, [0.8, -0.4], [0.2, 0.5], dt, n)
    tr = integrate(terms, [0.8, -0.4], [0.2, 0.5], dt, n)
    assert done == n and Q.shape == (n + 1, 2) and np.ptp(Q[:, 0]) > 1.0
    np.testing.assert_allclose(t, tr.time, atol=1e-12)
    np.testing.assert_allclose(Q, tr.q, atol=1e-5)
    np.testing.assert_allclose(P, tr.p, atol=1e-5)
    np.testing.assert_allclose(E, tr.energy, atol=1e-5)


def test_the_energy_does_not_drift():
    # anisotropic oscillator ½ q1² + 2 q2² with a coupled configuration-dependent mass
    _, batch = lagrangian(
        lambda x, y: 0.5 * x ** 2 + 2 * y ** 2, lambda x, y: [x, 4 * y],
        lambda x, y: [[1 + 0.2 * y ** 2, 0.05 * x * y], [0.05 * x * y, 1 + 0.3 * x ** 2]],
        lambda x, y: [[[Z(x.shape), 0.4 * y], [0.05 * y, 0.05 * x]],
                      [[0.05 * y, 0.05 * x], [0.6 * x, Z(x.shape)]]])
    tab = Table2D.from_batch(batch, [-1.5, -1.5], [1.5, 1.5], (65, 65))
    n = 100_000
    t, Q, P, E, done = integrate_table_2d(tab, [1.0, 0.3], [0.0, 0.4], 0.02, n)
    dev = np.abs(E - E[0]) / E[0]
    assert done == n and len(E) == n + 1 and 1e-5 < dev.max() < 0.05
    assert dev[-n // 10:].max() <= 2 * dev[:n // 10].max()
    assert t[-1] == pytest.approx(n * 0.02)
    t2, Q2, _, _, _ = integrate_table_2d(tab, [1.0, 0.3], [0.0, 0.4], 0.02, 1000, save_every=300)
    np.testing.assert_allclose(t2, [0, 6, 12, 18, 20], atol=1e-12)
    np.testing.assert_allclose(Q2, Q[[0, 300, 600, 900, 1000]], rtol=0, atol=1e-14)


def test_leaving_the_sampled_region_is_refused_with_the_states_reached():
    # free along q1 (p1 and q̇1 constant), an oscillator with a varying mass along q2
    _, batch = lagrangian(
        lambda x, y: 0.5 * y ** 2, lambda x, y: [Z(x.shape), y],
        lambda x, y: [[1 + Z(x.shape), Z(x.shape)], [Z(x.shape), 1 + 0.1 * y ** 2]],
        lambda x, y: [[[Z(x.shape), Z(x.shape)], [Z(x.shape), Z(x.shape)]],
                      [[Z(x.shape), Z(x.shape)], [Z(x.shape), 0.2 * y]]],
        region=lambda x, y: x < 0.52)                         # sampled for q1 ≤ 0.5
    tab = Table2D.from_batch(batch, [-1.0, -1.0], [1.0, 1.0], (41, 41))
    with pytest.raises(InputError, match="left the slow manifold's sampled region") as e:
        integrate_table_2d(tab, [-0.5, 0.2], [1.03, 0.3], 0.01, 1000, save_every=7)
    assert "step 98 " in str(e.value) and "sample a wider region" in str(e.value)
    t, Q, P = e.value.states
    assert len(t) > 1 and len(t) == len(Q) == len(P)
    assert t[-1] == pytest.approx(0.97) and tab.contains(Q[-1]) and 0.49 < Q[-1, 0] <= 0.5
    np.testing.assert_allclose(np.diff(t[:-1]), 0.07)


def test_a_step_newton_cannot_solve_is_cut_then_refused():
    # a stiff mass wall e^{40 (q1 − 1/2)} hit with a large step: the step has no solution
    _, batch = lagrangian(
        lambda x, y: 0.5 * y ** 2, lambda x, y: [Z(x.shape), y],
        lambda x, y: [[1 + np.exp(40 * (x - 0.5)), Z(x.shape)], [Z(x.shape), 1 + Z(x.shape)]],
        lambda x, y: [[[40 * np.exp(40 * (x - 0.5)), Z(x.shape)], [Z(x.shape), Z(x.shape)]],
                      [[Z(x.shape), Z(x.shape)], [Z(x.shape), Z(x.shape)]]])
    tab = Table2D.from_batch(batch, [-2.0, -1.0], [2.0, 1.0], (65, 33))
    with pytest.raises(InputError, match="Newton did not solve the reduced step") as e:
        integrate_table_2d(tab, [-1.0, 0.2], [1.0, 0.0], 0.5, 100, max_cuts=1)
    assert "lower the time step" in str(e.value)
    t, Q, P = e.value.states
    assert len(t) > 1 and Q.shape == (len(t), 2) and P.shape == (len(t), 2)
    t, Q, P, E, done = integrate_table_2d(tab, [-1.0, 0.2], [1.0, 0.0], 0.1, 100)
    assert done == 100


def test_a_start_outside_the_sampled_region_is_refused():
    _, batch = SMOOTH
    tab = Table2D.from_batch(lambda Q: (Q[:, 0] < 0.0,) + batch(Q)[1:], [-1.0, -1.0],
                             [1.0, 1.0], (9, 9))
    for q0 in ([1.5, 0.0], [0.5, 0.0], [np.nan, 0.0]):
        with pytest.raises(InputError, match="outside the slow manifold's sampled region"):
            integrate_table_2d(tab, q0, [0.0, 0.0], 0.01, 10)
    with pytest.raises(InputError, match="no cell of the 2-D table"):
        Table2D.from_batch(lambda Q: (Q[:, 0] < -0.9,) + batch(Q)[1:], [-1.0, -1.0],
                           [1.0, 1.0], (9, 9))
