"""The azimuthal moments L_{n,m} against adaptive quadrature of their definition, on both
branches (closed forms, trapezoidal rule) and near the singular and axis limits."""
import warnings

import numpy as np
import pytest
from scipy.integrate import quad

from pointatlas_physics.stokes_axisymmetric.azimuthal_moments import (M_SWITCH, PAIRS,
                                                                      azimuthal_moments)


def _reference(a, b, n, m, amb):
    # ρ² = (a − b) + 2b sin²(φ/2), with a − b exact
    f = lambda p: (1 - np.cos(p)) ** n * (amb + 2 * b * np.sin(p / 2) ** 2) ** (-m / 2)  # noqa
    me = 2 * b / (a + b)
    eps = np.sqrt(max(1 - me, 1e-30))
    br = [0, eps, 10 * eps, np.pi] if 10 * eps < np.pi else [0, np.pi]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        val = 2 * sum(quad(f, lo, hi, epsabs=0, epsrel=1e-13, limit=500)[0]
                      for lo, hi in zip(br[:-1], br[1:]))
    return val


@pytest.mark.parametrize("r, r0, dz", [
    (1.0, 1.0, 0.3), (1.0, 0.9, 0.0), (0.5, 1.5, 0.2), (2.0, 1e-3, 0.5), (1e-6, 1.0, 0.1),
    (1.0, 1.0, 1e-3), (0.3, 0.31, 0.01), (1.0, 0.0, 0.7)])
def test_moments_match_quadrature_of_their_definition(r, r0, dz):
    a, b, amb = r * r + r0 * r0 + dz * dz, 2 * r * r0, (r - r0) ** 2 + dz * dz
    L = azimuthal_moments(a, b, amb)
    for k, (n, m) in enumerate(PAIRS):
        ref = _reference(a, b, n, m, amb)
        assert L[k] == pytest.approx(ref, rel=1e-11, abs=1e-300), (n, m, 2 * b / (a + b))


def test_the_two_branches_agree_at_the_switch():
    a = 1.0
    b_sw = M_SWITCH * a / (2 - M_SWITCH)           # m = 2b/(a+b) = M_SWITCH
    lo, hi = azimuthal_moments(a, b_sw * (1 - 1e-12)), azimuthal_moments(a, b_sw * (1 + 1e-12))
    np.testing.assert_allclose(lo, hi, rtol=5e-12)


def test_the_axis_limit_is_the_uniform_ring():
    """b = 0 (a point on the axis): L_{n,m} = a^{−m/2} ∫ (1 − cos φ)^n dφ."""
    a = 2.0
    L = azimuthal_moments(a, 0.0)
    mean_u = {0: 2 * np.pi, 1: 2 * np.pi, 2: 3 * np.pi, 3: 5 * np.pi}
    for k, (n, m) in enumerate(PAIRS):
        assert L[k] == pytest.approx(mean_u[n] * a ** (-m / 2), rel=1e-14)


def test_shapes_broadcast():
    a = np.full((3, 4), 2.0)
    b = np.linspace(0, 1.9, 4)
    assert azimuthal_moments(a, b).shape == (3, 4, len(PAIRS))


def test_an_array_of_points_on_every_branch_matches_quadrature():
    """One call on many points (the threaded trapezoidal kernel and the closed forms side by
    side) gives each point's moments as adaptive quadrature does."""
    rng = np.random.default_rng(3)
    r, r0 = rng.uniform(1e-3, 2.0, 40), rng.uniform(1e-3, 2.0, 40)
    dz = rng.uniform(0.0, 1.5, 40)
    a, b, amb = r * r + r0 * r0 + dz * dz, 2 * r * r0, (r - r0) ** 2 + dz * dz
    m = 2 * b / (a + b)
    assert (m < 0.1).any() and ((m >= 0.1) & (m < M_SWITCH)).any() and (m >= M_SWITCH).any()
    L = azimuthal_moments(a, b, amb)
    for i in range(0, 40, 3):
        for k, (n, mm) in enumerate(PAIRS):
            ref = _reference(a[i], b[i], n, mm, amb[i])
            assert L[i, k] == pytest.approx(ref, rel=1e-11, abs=1e-300), (i, n, mm, m[i])
