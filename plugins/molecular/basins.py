"""Conformational basins of alanine dipeptide on (φ, ψ), and free energies on a CV grid
mapped onto (φ, ψ) through the CV's manifold (angles in degrees, energies in kJ/mol).

Basins by φ (the dihedral that separates them in vacuum; e.g. Apostolakis, Ferrara & Caflisch,
J. Chem. Phys. 110 (1999) 2099): C7eq at −130° < φ < −40° (apart from C5/β at φ ≈ −150°,
which in vacuum force fields is nearly as low, so a box over all φ < 0 could pick either),
C7ax/αL at 0 < φ < 120°. The β/C5 region wraps through φ = ±180°, so "φ > 0" alone would
count it as the C7ax side.
"""
from __future__ import annotations

import numpy as np

#: name → (φ_min, φ_max) in degrees
BASINS = {"C7eq": (-130.0, -40.0), "C7ax": (0.0, 120.0)}


def in_basin(phi, name: str) -> np.ndarray:
    lo, hi = BASINS[name]
    phi = np.asarray(phi, dtype=float)
    return (phi > lo) & (phi < hi)


def angular_distance(a, b) -> float:
    """Euclidean distance on the (φ, ψ) torus between a and b (degrees)."""
    d = (np.asarray(a, float) - np.asarray(b, float) + 180.0) % 360.0 - 180.0
    return float(np.sqrt(np.sum(d * d)))


def basin_minimum(A, phi, psi, name: str):
    """((φ, ψ), A) of the lowest finite A among the samples (cells) whose φ lies in the
    basin; (NaN, NaN), NaN if none. ``A``, ``phi``, ``psi`` of one shape."""
    A, phi, psi = (np.asarray(v, dtype=float).ravel() for v in (A, phi, psi))
    m = in_basin(phi, name) & np.isfinite(A)
    if not m.any():
        return (np.nan, np.nan), np.nan
    i = np.flatnonzero(m)[np.argmin(A[m])]
    return (phi[i], psi[i]), A[i]


def grid_dihedrals(manifold, centres, quads) -> np.ndarray:
    """(n1, …, len(quads)) dihedrals (degrees) of the manifold's configurations X(ξ) at the
    grid of CV cell centres (one array per axis); NaN where X is undefined (outside the
    parametrised region). ``quads``: atom positions within a configuration (n_atoms, 3)."""
    from .engine import dihedrals

    mesh = np.meshgrid(*centres, indexing="ij")
    q = np.stack([m.ravel() for m in mesh], axis=1)
    out = np.full((len(q), len(quads)), np.nan)
    for i, qi in enumerate(q):
        if manifold.contains(qi):
            X = np.asarray(manifold.evaluate(qi[None])[0]).reshape(1, -1, 3)
            out[i] = dihedrals(X, quads)[0]
    return out.reshape(mesh[0].shape + (len(quads),))
