"""Point sets for the embedder tests, generated with numpy (no plugin dependency)."""
from __future__ import annotations

import numpy as np
import pytest


def make_swiss_roll(n: int, seed: int = 0):
    """Swiss roll x = (t cos t, h, t sin t), t ~ U(1.5 pi, 4.5 pi), h ~ U(0, 21).

    Returns points (n, 3) and the unrolled coordinates (arc length s(t), h), an isometric
    parametrisation: s(t) = (t sqrt(1 + t^2) + asinh t) / 2.
    """
    rng = np.random.default_rng(seed)
    t = 1.5 * np.pi * (1 + 2 * rng.random(n))
    h = 21 * rng.random(n)
    s = 0.5 * (t * np.sqrt(1 + t * t) + np.arcsinh(t))
    return np.c_[t * np.cos(t), h, t * np.sin(t)], np.c_[s, h]


def make_quarter_truncated_sphere(n_sphere: int = 2400, z_min: float = -0.5):
    """Quasi-uniform (Fibonacci) points of the unit sphere with z >= z_min, x >= 0, y >= 0.

    The quarter of a truncated sphere of thesis Fig. 6 / Table 1 (exact sampling not given):
    the sphere cut below z = -0.5, then quartered. Keeps about n_sphere * 0.1875 points.
    """
    i = np.arange(n_sphere) + 0.5
    z = 1 - 2 * i / n_sphere
    phi = np.pi * (1 + 5 ** 0.5) * i
    r = np.sqrt(1 - z * z)
    P = np.c_[r * np.cos(phi), r * np.sin(phi), z]
    keep = (P[:, 2] >= z_min) & (P[:, 0] >= 0) & (P[:, 1] >= 0)
    return P[keep]


@pytest.fixture(scope="session")
def swiss_roll():
    return make_swiss_roll(800)


@pytest.fixture(scope="session")
def quarter_sphere():
    return make_quarter_truncated_sphere()
