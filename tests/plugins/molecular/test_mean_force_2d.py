"""2-D CZAR and Poisson integration against analytic fields and exact Gaussian samples."""
import numpy as np

from pointatlas_molecular.mean_force_2d import czar_gradient_2d, integrate_2d


def _grid(n1, n2, lo, hi):
    w = (np.asarray(hi) - lo) / [n1, n2]
    c1 = lo[0] + w[0] * (np.arange(n1) + 0.5)
    c2 = lo[1] + w[1] * (np.arange(n2) + 0.5)
    return np.meshgrid(c1, c2, indexing="ij"), w


def test_integrates_an_exact_gradient_field_with_a_hole():
    (x, y), w = _grid(30, 24, np.array([-1.0, -1.0]), np.array([1.0, 1.0]))
    A = 3 * x ** 2 + np.sin(2 * y) + x * y
    g = np.stack([6 * x + y, 2 * np.cos(2 * y) + x], axis=-1)
    g[12:15, 10:13] = np.nan                      # an unsampled patch inside
    got = integrate_2d(g, w)
    ok = np.isfinite(got)
    assert ok.sum() == 30 * 24 - 9
    ref = A - A[ok].min()
    err = (got - got[ok].mean()) - (ref - ref[ok].mean())
    assert np.max(np.abs(err[ok])) < 0.02 * np.ptp(A)


def test_periodic_axes_close_round():
    (x, y), w = _grid(36, 36, np.array([-np.pi, -np.pi]), np.array([np.pi, np.pi]))
    g = np.stack([np.cos(x) * np.cos(y), -np.sin(x) * np.sin(y)], axis=-1)
    got = integrate_2d(g, w, periodic=(True, True))
    ref = np.sin(x) * np.cos(y)
    assert np.max(np.abs((got - got.mean()) - (ref - ref.mean()))) < 0.01


def test_czar_2d_on_exact_extended_samples_with_a_bias_on_lambda():
    """Joint exp(−β[A(z) + Σ k/2 (z_a − λ_a)² + B(λ)]), A = z·S z/2, B = b|λ|²/2: Gaussian in
    R⁴, sampled exactly; CZAR must give ∇A = S z."""
    kT, k, b = 2.5, 300.0, 20.0
    S = np.array([[30.0, 8.0], [8.0, 20.0]])
    P = np.zeros((4, 4))
    P[:2, :2] = S + k * np.eye(2)
    P[:2, 2:] = P[2:, :2] = -k * np.eye(2)
    P[2:, 2:] = (k + b) * np.eye(2)
    s = np.random.default_rng(2).multivariate_normal(np.zeros(4), np.linalg.inv(P / kT),
                                                     3_000_000)
    z, lam = s[:, :2], s[:, 2:]
    lo, hi, n = np.array([-0.7, -0.7]), np.array([0.7, 0.7]), 14
    w = (hi - lo) / n
    ij = np.floor((z - lo) / w).astype(int)
    inside = np.all((ij >= 0) & (ij < n), axis=1)
    flat = ij[inside, 0] * n + ij[inside, 1]
    cnt = np.bincount(flat, minlength=n * n).reshape(n, n)
    sums = np.stack([np.bincount(flat, weights=(lam - z)[inside, a], minlength=n * n)
                     for a in range(2)], axis=-1).reshape(n, n, 2)
    g = czar_gradient_2d(cnt, sums, w, k, kT, min_count=10_000)
    (x, y), _ = _grid(n, n, lo, hi)
    ref = np.stack([S[0, 0] * x + S[0, 1] * y, S[1, 0] * x + S[1, 1] * y], axis=-1)
    ok = np.all(np.isfinite(g), axis=-1)
    assert ok.sum() >= 20
    assert np.max(np.abs(g[ok] - ref[ok])) < 1.5
