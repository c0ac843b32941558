"""The crack energy kernel: its derivatives, and the 1-d identity behind the crack-band bar."""
import numpy as np
from hypothesis import given, settings, strategies as st
from scipy.integrate import quad

from pointatlas_physics.kirchhoff_love_fracture.phase_field import CrackEnergy, degradation


def _point(seed):
    rng = np.random.default_rng(seed)
    J = rng.normal(size=(2, 2)) + 2 * np.eye(2)
    A = np.linalg.inv(J @ J.T)                   # an inverse metric (SPD)
    data = np.array([[A[0, 0], A[0, 1], A[1, 1], rng.uniform(0, 3)]])
    return rng.normal(size=(1, 3)), data


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000), model=st.sampled_from(["at2", "at1"]))
def test_gradient_and_hessian_match_finite_differences(seed, model):
    e = CrackEnergy(2.0, 0.1, 0.05, 1e-3, model=model)
    jet, data = _point(seed)
    _, g, H = e.evaluate(jet, data, 2)
    h = 1e-6
    for r in range(3):
        d = np.zeros_like(jet)
        d[0, r] = h
        Wp = e.evaluate(jet + d, data, 0)[0].sum()
        Wm = e.evaluate(jet - d, data, 0)[0].sum()
        gp = e.evaluate(jet + d, data, 1)[1]
        gm = e.evaluate(jet - d, data, 1)[1]
        assert abs((Wp - Wm) / (2 * h) - g[0, r]) < 1e-6 * max(1.0, abs(g[0, r]))
        np.testing.assert_allclose((gp - gm)[0] / (2 * h), H[0, :, r], rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(H[0], H[0].T)


def test_the_exact_band_has_energy_gc_h_per_unit_length():
    """Across υ(x) = 1 − exp(−|x|/2κ̄) the density integrates to G_c h (thesis §4: the
    regularised energy of a straight crack is G_c h L); the kernel's own formula is
    integrated, on a plane with the identity metric."""
    Gc, h, k = 3.0, 0.2, 0.07
    e = CrackEnergy(Gc, h, k, 1e-6)

    def density(x):
        v = 1 - np.exp(-abs(x) / (2 * k))
        dv = np.sign(x) * np.exp(-abs(x) / (2 * k)) / (2 * k)
        jet = np.array([[v, dv, 0.0]])
        return e.evaluate(jet, np.array([[1.0, 0.0, 1.0, 0.0]]), 0)[0][0, 0]

    total = 2 * quad(density, 0, 60 * k, limit=200)[0]
    assert abs(total / (Gc * h) - 1) < 1e-10


def test_the_band_is_the_minimiser_in_one_dimension():
    """υ − 4κ̄² υ'' = 1 (the Euler–Lagrange equation of the crack energy) holds for
    1 − exp(−|x|/2κ̄) off the crack: the kernel's gradient in weak form vanishes against
    smooth test functions supported away from x = 0."""
    k = 0.05
    e = CrackEnergy(1.0, 1.0, k, 0.0)
    x = np.linspace(0.02, 0.6, 20001)
    v = 1 - np.exp(-x / (2 * k))
    dv = np.exp(-x / (2 * k)) / (2 * k)
    jets = np.column_stack([v, dv, np.zeros_like(x)])
    data = np.tile([1.0, 0.0, 1.0, 0.0], (len(x), 1))
    g = e.evaluate(jets, data, 1)[1]
    phi = np.sin(np.pi * (x - 0.02) / 0.58) ** 2          # vanishes at both ends
    dphi = np.pi / 0.58 * np.sin(2 * np.pi * (x - 0.02) / 0.58)
    weak = np.trapezoid(g[:, 0] * phi + g[:, 1] * dphi, x)
    assert abs(weak) < 1e-8


def test_the_at1_band_has_energy_gc_h_per_unit_length():
    """AT1's compact band υ = 1 − (1 − |x|/4κ̄)² (|x| < 4κ̄) integrates to G_c h too, and
    it is not AT2's: the AT2 kernel on the same profile gives another number."""
    Gc, h, k = 3.0, 0.2, 0.07
    e1, e2 = (CrackEnergy(Gc, h, k, 1e-6, model=m) for m in ("at1", "at2"))

    def density(x, e):
        s = max(1 - abs(x) / (4 * k), 0.0)
        jet = np.array([[1 - s * s, np.sign(x) * 2 * s / (4 * k), 0.0]])
        return e.evaluate(jet, np.array([[1.0, 0.0, 1.0, 0.0]]), 0)[0][0, 0]

    at1 = 2 * quad(density, 0, 4 * k, args=(e1,), limit=200)[0]
    at2 = 2 * quad(density, 0, 4 * k, args=(e2,), limit=200)[0]
    assert abs(at1 / (Gc * h) - 1) < 1e-10
    assert abs(at2 / (Gc * h) - 1) > 0.05


def test_at1_has_an_elastic_threshold_and_at2_none():
    """The homogeneous stationarity ∂W/∂υ = 0 at υ = 1: the at1 gradient at υ = 1 changes
    sign at ψ_c = 3 G_c h/(32κ̄) (below it the bound υ ≤ 1 holds υ at 1), and above it the
    stationary point is υ = ψ_c/ψ; at2's gradient at υ = 1 is 2ψ > 0 for every ψ > 0."""
    Gc, h, k = 1e-3, 0.1, 0.05
    e1, e2 = (CrackEnergy(Gc, h, k, 1e-6, model=m) for m in ("at1", "at2"))
    psi_c = 3 * Gc * h / (32 * k)
    assert e1.threshold() == psi_c and e2.threshold() == 0.0

    def slope(e, v, psi):
        return e.evaluate(np.array([[v, 0.0, 0.0]]), np.array([[1.0, 0.0, 1.0, psi]]), 1)[1][0, 0]

    assert slope(e1, 1.0, 0.99 * psi_c) < 0 < slope(e1, 1.0, 1.01 * psi_c)
    assert abs(slope(e1, psi_c / (2 * psi_c), 2 * psi_c)) < 1e-15
    assert slope(e2, 1.0, 1e-3 * psi_c) > 0


def test_degradation():
    assert degradation(1.0, 1e-3) == 1.0 + 1e-3 and degradation(0.0, 1e-3) == 1e-3
