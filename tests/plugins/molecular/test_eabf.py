"""CZAR and the integration of a mean-force profile against exact Gaussian samples."""
import numpy as np
import pytest

from pointatlas_molecular.eabf import EABF, czar_gradient, integrate_gradient, wrap


@pytest.mark.parametrize("b", [0.0, 30.0, -8.0])
def test_czar_recovers_the_free_energy_whatever_the_bias_on_lambda(b):
    """Joint density exp(−β[A(z) + k/2 (z − λ)² + B(λ)]) with A = a z²/2, B = b λ²/2: a 2-D
    Gaussian sampled exactly; CZAR must return A'(z) = a z for any bias B on λ alone."""
    kT, a, k = 2.5, 40.0, 400.0
    prec = np.array([[a + k, -k], [-k, k + b]]) / kT
    cov = np.linalg.inv(prec)
    zl = np.random.default_rng(1).multivariate_normal([0, 0], cov, 4_000_000)
    e = EABF(-0.6, 0.6, 24, k=k, mass=1.0, kT=kT)
    idx = np.array([e.bin(v) for v in zl[:200_000, 0]])  # bin() agrees with the vector path
    vec = np.floor((zl[:200_000, 0] + 0.6) / e.width).astype(int)
    inside = (vec >= 0) & (vec < 24)
    assert np.all(idx[inside] == vec[inside])
    b_all = np.floor((zl[:, 0] + 0.6) / e.width).astype(int)
    ok = (b_all >= 0) & (b_all < 24)
    cnt = np.bincount(b_all[ok], minlength=24)
    s = np.bincount(b_all[ok], weights=(zl[:, 1] - zl[:, 0])[ok], minlength=24)
    g = czar_gradient(cnt, s, e.width, k, kT, periodic=False, min_count=20_000)
    z = e.centres()
    good = np.isfinite(g)
    assert good.sum() >= 10
    # statistical noise of d ln ρ̃/dz at ≥ 2e4 samples per bin: ~0.3 kJ/mol/[ξ]
    assert np.max(np.abs(g[good] - a * z[good])) < 0.06 * a * 0.6


def test_periodic_integration_of_a_sine_gradient():
    n = 72
    w = 2 * np.pi / n
    z = -np.pi + w * (np.arange(n) + 0.5)
    A, closure = integrate_gradient(3.0 * np.sin(z) + 0.2, w, periodic=True)
    expected = -3.0 * np.cos(z)
    assert abs(closure - 0.2) < 1e-12
    assert np.max(np.abs((A - A.mean()) - (expected - expected.mean()))) < 0.01


def test_integration_keeps_the_longest_valid_run_only():
    g = np.array([1.0, 1.0, np.nan, 2.0, 2.0, 2.0, np.nan])
    A, _ = integrate_gradient(g, 0.5, periodic=False)
    assert np.all(np.isnan(A[[0, 1, 2, 6]]))
    assert np.allclose(A[3:6], [0.0, 1.0, 2.0])


def test_wrap_and_periodic_bins():
    assert wrap(3.5, 2 * np.pi) == pytest.approx(3.5 - 2 * np.pi)
    e = EABF(-np.pi, np.pi, 8, k=1.0, mass=1.0, kT=1.0, period=2 * np.pi)
    assert e.bin(np.pi + 0.1) == 0 and e.bin(-np.pi - 0.1) == 7


def test_abf_flattens_a_harmonic_lambda_bias_free_walk():
    """λ alone (no atoms: ξ held at 0): with ABF the bias learns −k(0 − λ) and λ spreads over
    the whole range instead of staying within a few kT/k of 0."""
    kT, k = 2.5, 50.0
    e = EABF(-1.0, 1.0, 10, k=k, mass=0.05, kT=kT, friction=5.0, full_samples=50)
    rng = np.random.default_rng(0)
    lam = []
    for _ in range(60_000):
        e.step(0.0, rng, 0.002)
        lam.append(e.lam)
    lam = np.array(lam[20_000:])
    counts = np.histogram(lam, bins=10, range=(-1, 1))[0]
    assert counts.min() > 0.3 * counts.mean()
    centres = e.centres()
    learnt = -e.f_sum / np.maximum(e.f_count, 1)      # the bias force per bin
    assert np.allclose(learnt, k * centres, rtol=0.15, atol=0.1 * k * 0.1)
