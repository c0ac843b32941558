"""eABF on a grid: the 1-D view :class:`EABF` steps as the scheme written out, walls keep λ inside, ABF flattens a
2-D coupling well, and CZAR + Poisson recover a 2-D free energy from exact samples."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pointatlas.errors import ConfigError
from pointatlas_molecular.eabf import EABF
from pointatlas_molecular.eabf_grid import EABFGrid


def reference_baoab(lam, vel, xi, f_mean, k, mass, kT, friction, dt, noise, lo, hi, period):
    """One eABF step of λ written out by hand (no wall hit in the test), as the scheme reads:
    half kick with k (ξ − λ) + bias, half drift, O step, half drift, half kick at the new λ."""
    w = (lambda d: d) if period is None else (lambda d: (d + period / 2) % period - period / 2)
    fold = (lambda v: v) if period is None else (lambda v: lo + (v - lo) % period)
    vel += 0.5 * dt * (k * w(xi - lam) + f_mean(lam)) / mass
    lam = fold(lam + 0.5 * dt * vel)
    c = np.exp(-friction * dt)
    vel = c * vel + np.sqrt((1 - c * c) * kT / mass) * noise
    lam = fold(lam + 0.5 * dt * vel)
    vel += 0.5 * dt * (k * w(xi - lam) + f_mean(lam)) / mass
    return lam, vel


@pytest.mark.parametrize("period", [None, 2.0])
def test_one_cv_view_steps_as_the_scheme_written_out(period):
    """EABF (the 1-D view of EABFGrid) against the BAOAB step written out in the test, with
    the bias read from its accumulators before each step; and the view's state is the
    grid's."""
    kw = dict(k=30.0, mass=0.05, kT=2.5, friction=5.0, full_samples=20)
    a = EABF(-1.0, 1.0, 10, period=period, lam=0.1, **kw)
    rng, noise = np.random.default_rng(5), np.random.default_rng(5)
    xs = np.random.default_rng(6).uniform(-0.3, 0.3, 400)
    for x in xs:
        lam, vel = a.lam, a.vel
        bl = a.bin(lam)
        f_sum, f_count = a.f_sum.copy(), a.f_count.copy()
        f_sum[bl] += a.coupling(x)
        f_count[bl] += 1

        def f_mean(v):
            b = a.bin(v)
            n = f_count[b]
            return 0.0 if b < 0 or n == 0 else -min(1.0, n / 20) * f_sum[b] / n

        expected = reference_baoab(lam, vel, x, f_mean, noise=noise.normal(), lo=-1.0,
                                   hi=1.0, period=period, dt=0.002,
                                   **{n: kw[n] for n in ("k", "mass", "kT", "friction")})
        a.step(x, rng, 0.002)
        assert a.lam == pytest.approx(expected[0], abs=1e-12)
        assert a.vel == pytest.approx(expected[1], abs=1e-9)
    assert a.grid.lam[0] == a.lam and np.array_equal(a.f_sum, a.grid.f_sum[:, 0])
    assert a.f_count.sum() == len(xs) and a.z_count.sum() == len(xs)


@settings(max_examples=10, deadline=None)
@given(st.integers(0, 10_000))
def test_lambda_never_leaves_a_convex_region(seed):
    """A triangle inside the box: λ, diffusing with ABF and no coupling pull toward it, stays
    inside the triangle."""
    from scipy.spatial import ConvexHull

    tri = np.array([[-0.8, -0.8], [0.9, -0.5], [-0.2, 0.9]])
    eq = ConvexHull(tri).equations
    e = EABFGrid([-1, -1], [1, 1], 8, k=1.0, mass=0.01, kT=2.5, friction=2.0, region=eq,
                 lam=[-0.1, -0.2])
    rng = np.random.default_rng(seed)
    for _ in range(3000):
        e.step(e.lam, rng, 0.002)
        assert np.all(eq[:, :2] @ e.lam + eq[:, 2] <= 1e-12)


def test_a_start_outside_the_region_is_refused():
    from scipy.spatial import ConvexHull

    eq = ConvexHull(np.array([[0, 0], [1, 0], [0, 1.0]])).equations
    with pytest.raises(ConfigError, match="outside the eABF range"):
        EABFGrid([0, 0], [1, 1], 4, k=1, mass=1, kT=1, region=eq, lam=[0.9, 0.9])


def test_abf_learns_the_coupling_force_in_two_dimensions():
    """ξ held at 0: the bias learns −k_a(0 − λ_a) per axis and λ covers the box."""
    kT, k = 2.5, np.array([50.0, 20.0])
    e = EABFGrid([-1, -1], [1, 1], (6, 5), k=k, mass=0.05, kT=kT, friction=5.0,
                 full_samples=50, lam=[0, 0])
    rng = np.random.default_rng(0)
    for _ in range(120_000):
        e.step([0.0, 0.0], rng, 0.002)
    assert np.all(e.f_count > 0)
    learnt = -e.f_sum / e.f_count[:, None]
    c1, c2 = np.meshgrid(e.centres(0), e.centres(1), indexing="ij")
    expect = np.stack([k[0] * c1.ravel(), k[1] * c2.ravel()], axis=1)
    assert np.max(np.abs(learnt - expect)) < 0.2 * np.max(np.abs(expect))


def test_free_energy_of_exact_gaussian_samples():
    """Joint density ∝ exp(−β[A(z) + Σ k/2 (z_a − λ_a)²]) with A = Σ a_a z_a²/2 sampled
    exactly (λ unbiased): A recovered on the grid within the sampling noise."""
    kT, k, a = 2.5, 400.0, np.array([40.0, 80.0])
    e = EABFGrid([-0.6, -0.45], [0.6, 0.45], 12, k=k, mass=1.0, kT=kT, lam=[0, 0])
    rng = np.random.default_rng(2)
    n = 6_000_000
    zl = np.empty((n, 2, 2))
    for ax in range(2):
        prec = np.array([[a[ax] + k, -k], [-k, k]]) / kT
        zl[:, ax] = rng.multivariate_normal([0, 0], np.linalg.inv(prec), n)
    z, lam = zl[:, :, 0], zl[:, :, 1]
    idx = np.floor((z - e.lower) / e.width).astype(int)
    ok = np.all((idx >= 0) & (idx < 12), axis=1)
    flat = np.ravel_multi_index(tuple(idx[ok].T), e.n_bins)
    e.z_count[:] = np.bincount(flat, minlength=144)
    for ax in range(2):
        e.z_lam_sum[:, ax] = np.bincount(flat, weights=(lam - z)[ok, ax], minlength=144)
    A, _ = e.free_energy(min_count=2000)
    c1, c2 = np.meshgrid(e.centres(0), e.centres(1), indexing="ij")
    exact = 0.5 * (a[0] * c1 ** 2 + a[1] * c2 ** 2)
    good = np.isfinite(A)
    assert good.sum() >= 40
    d = (A - exact)[good]
    assert np.max(np.abs(d - d.mean())) < 0.5          # kJ/mol, A spans ~7 kJ/mol here
