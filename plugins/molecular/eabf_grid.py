"""Extended-system ABF on d collective variables (d = 1, 2, …) on a grid of bins, with
reflecting walls at the box and, optionally, at a convex region (the parametrised region of
a SandCV). Units as :mod:`.eabf`: ξ, λ in the CV units [ξ_a]; k in kJ/mol/[ξ_a]²; mass in
kJ/mol ps²/[ξ_a]²; kT in kJ/mol; dt in ps.

The scheme is :mod:`.eabf`'s, per axis: λ ∈ R^d is coupled to ξ(x) by ½ Σ_a k_a (ξ_a − λ_a)²;
the atoms feel −Σ_a k_a (ξ_a − λ_a) ∂ξ_a/∂x; λ feels F_λ = k (ξ − λ) plus the ABF bias, minus
the ramped running mean of F_λ in λ's bin (Lelièvre, Rousset & Stoltz, J. Chem. Phys. 126
(2007) 134111). Free energy of ξ by CZAR per axis (Lesage et al., J. Phys. Chem. B 121 (2017)
3676, Eq. 12) from the accumulated counts of z = ξ and sums of λ − z
(:func:`.mean_force_2d.czar_gradient_2d`, then :func:`.mean_force_2d.integrate_2d`).

Walls: a non-periodic axis reflects λ at [lower, upper] (mirror position, reverse velocity);
with ``region`` (facet inequalities n·λ + c ≤ 0, unit n, as scipy's ``ConvexHull.equations``)
a drift that leaves the region is undone and the velocity reflected specularly on the most
violated facet, so λ never asks ξ for a value the CV cannot take.
"""
from __future__ import annotations

import numpy as np

from pointatlas.errors import ConfigError

from .eabf_kernel import coupling, eabf_step, flat_bin


class EABFGrid:
    """λ, its Langevin dynamics, and the ABF (on λ) and CZAR (on z) accumulators per bin."""

    def __init__(self, lower, upper, n_bins, k, mass, kT, friction=10.0, full_samples=200,
                 periods=None, region=None, lam=None):
        self.lower = np.atleast_1d(np.asarray(lower, dtype=float))
        self.upper = np.atleast_1d(np.asarray(upper, dtype=float))
        d = self.dim = len(self.lower)
        self.n_bins = tuple(int(n) for n in np.broadcast_to(n_bins, (d,)))
        self.k = np.broadcast_to(np.asarray(k, dtype=float), (d,)).copy()
        self.mass = np.broadcast_to(np.asarray(mass, dtype=float), (d,)).copy()
        self.kT, self.friction, self.full_samples = float(kT), float(friction), int(full_samples)
        self.periods = np.full(d, np.nan) if periods is None else \
            np.array([np.nan if p is None else float(p) for p in periods])
        self.region = None if region is None else np.asarray(region, dtype=float)
        if not np.all(self.lower < self.upper):
            raise ConfigError(f"eABF box lower {self.lower} must lie below upper {self.upper} "
                              f"on every axis.")
        self.width = (self.upper - self.lower) / np.array(self.n_bins)
        self.lam = (0.5 * (self.lower + self.upper) if lam is None
                    else np.atleast_1d(np.asarray(lam, dtype=float)).copy())
        if not self.inside(self.lam):
            raise ConfigError(f"the starting configuration's CV value {np.round(self.lam, 4)} "
                              f"lies outside the eABF range; widen the range or start "
                              f"elsewhere.")
        self.vel = np.zeros(d)
        self._n_bins = np.array(self.n_bins, dtype=np.int64)
        self._region_rows = (np.zeros((0, d + 1)) if self.region is None
                             else np.ascontiguousarray(self.region))
        B = int(np.prod(self.n_bins))
        self.f_sum, self.f_count = np.zeros((B, d)), np.zeros(B, dtype=np.int64)
        self.z_count, self.z_lam_sum = np.zeros(B, dtype=np.int64), np.zeros((B, d))

    # -- geometry ---------------------------------------------------------------------------
    def bin(self, v) -> int:
        """Flat (C-order) bin of a CV value; −1 outside the box."""
        v = np.atleast_1d(np.asarray(v, dtype=float))
        return int(flat_bin(v, self.lower, self.width, self._n_bins, self.periods))

    def centres(self, axis: int) -> np.ndarray:
        return self.lower[axis] + self.width[axis] * (np.arange(self.n_bins[axis]) + 0.5)

    def inside(self, lam) -> bool:
        lam = np.asarray(lam, dtype=float)
        box = ~np.isnan(self.periods) | ((lam >= self.lower) & (lam <= self.upper))
        if not np.all(box):
            return False
        return self.region is None or bool(np.all(self.region[:, :-1] @ lam
                                                  + self.region[:, -1] <= 0.0))

    # -- dynamics ---------------------------------------------------------------------------
    def coupling(self, xi) -> np.ndarray:
        """k (ξ − λ) per axis: the force on λ and, times −∂ξ_a/∂x, on the atoms."""
        f = np.empty(self.dim)
        coupling(f, np.atleast_1d(np.asarray(xi, dtype=float)), self.lam, self.k, self.periods)
        return f

    def check_time_step(self, dt: float) -> None:
        """λ's oscillation 2π √(m/k) must span ≥ 10 time steps on every axis."""
        T = 2 * np.pi * np.sqrt(self.mass / self.k)
        if np.any(T < 10 * dt):
            a = int(np.argmin(T))
            raise ConfigError(
                f"the extended variable oscillates with period {T[a]:.3g} ps on axis {a}, "
                f"under 10 time steps of {dt:g} ps: its integration would blow up. Raise its "
                f"mass to at least {self.k[a] * (10 * dt / (2 * np.pi)) ** 2:.3g} or lower the "
                f"coupling.")

    def bias(self, b: int) -> np.ndarray:
        """Minus the ramped running mean of F_λ in bin b (0 outside the box)."""
        if b < 0 or self.f_count[b] == 0:
            return np.zeros(self.dim)
        n = self.f_count[b]
        return -min(1.0, n / self.full_samples) * self.f_sum[b] / n

    def step(self, xi, rng: np.random.Generator, dt: float) -> None:
        """Accumulate at (ξ, λ), then advance λ by one BAOAB step of Langevin dynamics
        (:func:`.eabf_kernel.eabf_step`; one normal draw per axis from ``rng``)."""
        xi = np.ascontiguousarray(xi, dtype=float)
        noise = rng.normal(size=self.dim)
        if self.lam.dtype != np.float64 or self.vel.dtype != np.float64:
            self.lam, self.vel = self.lam.astype(float), self.vel.astype(float)
        region = self._region_rows
        eabf_step(self.lam, self.vel, xi, noise, float(dt), self.lower, self.upper, self.width,
                  self._n_bins, self.periods, region, self.k, self.mass, self.kT,
                  self.friction, self.full_samples, self.f_sum, self.f_count, self.z_count,
                  self.z_lam_sum)

    # -- estimator --------------------------------------------------------------------------
    def free_energy(self, min_count: int = 20):
        """(A on the grid (kJ/mol, min 0, NaN unsampled), its gradient (…, d)) by CZAR and, in
        2-D, the least-squares Poisson integration; d = 2 only."""
        from .mean_force_2d import czar_gradient_2d, integrate_2d

        if self.dim != 2:
            raise ConfigError(f"free_energy() integrates 2-D grids; this eABF has d = "
                              f"{self.dim} (use eabf.czar_gradient for one CV).")
        per = tuple(bool(p) for p in ~np.isnan(self.periods))
        g = czar_gradient_2d(self.z_count.reshape(self.n_bins),
                             self.z_lam_sum.reshape(self.n_bins + (2,)), self.width, self.k,
                             self.kT, per, min_count=min_count)
        return integrate_2d(g, self.width, per), g
