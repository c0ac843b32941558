"""Extended-system adaptive biasing force (eABF) on one collective variable, and the CZAR
estimate of the free-energy gradient (kJ/mol; ξ in its own unit, rad for a dihedral).

Which ABF this is. A fictitious particle λ (mass m, Langevin at the system's temperature) is
coupled to ξ(x) by ½ k (ξ(x) − λ)²; the atoms feel −k (ξ − λ) ∂ξ/∂x, λ feels
F_λ = k (ξ − λ). ABF acts on λ only: the running mean of F_λ in λ's bin, ramped in by
min(1, n/``full_samples``), is subtracted, so λ diffuses freely along the CV range and drags
ξ with it (Lelièvre, Rousset & Stoltz, J. Chem. Phys. 126 (2007) 134111; Zheng & Yang,
J. Chem. Theory Comput. 8 (2012) 810). Neither the metric Z = J M⁻¹ Jᵀ nor second derivatives
of ξ enter the bias, so the Jacobian term of classical ABF cannot be got wrong here; it
reappears, exactly, in the estimator. The free energy of ξ, A(z) = −kT ln ρ(z), follows from
the *corrected z-averaged restraint* (CZAR; Lesage, Lelièvre, Stoltz & Hénin, J. Phys. Chem.
B 121 (2017) 3676, Eq. 12):

    A'(z) = −kT d ln ρ̃(z)/dz + k (⟨λ⟩_z − z),

ρ̃ the biased histogram of z = ξ(x) and ⟨λ⟩_z the mean of λ over samples with ξ = z, valid
for any bias that acts on λ alone. Outside [lower, upper] λ is reflected (non-periodic CVs).
"""
from __future__ import annotations

import numpy as np


def wrap(d, period):
    """d folded into [−period/2, period/2) (periodic CVs); unchanged if period is None."""
    return d if period is None else (d + 0.5 * period) % period - 0.5 * period


class EABF:
    """eABF on one CV: a 1-D view of :class:`.eabf_grid.EABFGrid` (one axis; the dynamics
    and accumulators are the grid's), with scalar ``lam``, ``vel``, ``width`` and per-bin
    ``f_sum``, ``z_lam_sum`` arrays (n_bins,).

    Units: ξ, λ in the CV unit [ξ]; k in kJ/mol/[ξ]²; mass in kJ/mol ps²/[ξ]²; friction
    1/ps; kT in kJ/mol; dt in ps.
    """

    def __init__(self, lower: float, upper: float, n_bins: int, k: float, mass: float,
                 kT: float, friction: float = 10.0, full_samples: int = 200,
                 period: float | None = None, lam: float = 0.0, vel: float = 0.0):
        from pointatlas.errors import ConfigError

        from .eabf_grid import EABFGrid

        if not lower < upper:
            raise ConfigError(f"eABF range [{lower:g}, {upper:g}] is empty; give "
                              f"lower < upper.")
        if not lower <= lam <= upper:
            raise ConfigError(f"the starting configuration's CV value {lam:g} lies outside "
                              f"the eABF range [{lower:g}, {upper:g}]; widen the "
                              f"range or start elsewhere.")
        self.lower, self.upper, self.n_bins = float(lower), float(upper), int(n_bins)
        self.k, self.mass, self.kT = float(k), float(mass), float(kT)
        self.friction, self.full_samples, self.period = float(friction), int(full_samples), period
        self.grid = EABFGrid([lower], [upper], n_bins, k, mass, kT, friction=friction,
                             full_samples=full_samples, periods=[period], lam=[lam])
        self.grid.vel[0] = vel
        self.width = float(self.grid.width[0])

    # the state, as scalars and (n_bins,) arrays (views of the grid's)
    lam = property(lambda self: float(self.grid.lam[0]),
                   lambda self, v: self.grid.lam.__setitem__(0, v))
    vel = property(lambda self: float(self.grid.vel[0]),
                   lambda self, v: self.grid.vel.__setitem__(0, v))
    f_sum = property(lambda self: self.grid.f_sum[:, 0])
    f_count = property(lambda self: self.grid.f_count)
    z_count = property(lambda self: self.grid.z_count)
    z_lam_sum = property(lambda self: self.grid.z_lam_sum[:, 0])

    def bin(self, v: float) -> int:
        """Bin of a CV value (−1 outside a non-periodic range)."""
        return self.grid.bin([v])

    def centres(self) -> np.ndarray:
        return self.grid.centres(0)

    def coupling(self, xi: float) -> float:
        """k (ξ − λ): the force on λ and, times −∂ξ/∂x, the force on the atoms."""
        return float(self.grid.coupling([xi])[0])

    def period_of_lambda(self) -> float:
        """Oscillation period 2π √(m/k) of λ in the coupling well (ps)."""
        return 2 * np.pi * np.sqrt(self.mass / self.k)

    def check_time_step(self, dt: float) -> None:
        """λ's oscillation must span ≥ 10 time steps, or its integration is unstable."""
        self.grid.check_time_step(dt)

    def step(self, xi: float, rng: np.random.Generator, dt: float) -> None:
        """Accumulate at (ξ, λ), then advance λ by one BAOAB step of Langevin dynamics."""
        self.grid.step([xi], rng, dt)

    def bias(self, b: int) -> float:
        """Minus the ramped running mean of F_λ in bin b (0 outside the range)."""
        return float(self.grid.bias(b)[0])


def czar_gradient(z_count, z_lam_sum, width, k, kT, periodic, min_count=20):
    """A'(z) per bin (kJ/mol/[ξ]) from the CZAR accumulators; NaN where a bin or one of its
    neighbours has fewer than ``min_count`` samples."""
    n = np.asarray(z_count, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        lnr = np.where(n > 0, np.log(n), np.nan)
        mean_lz = np.where(n > 0, z_lam_sum / n, np.nan)
    if periodic:
        dln = (np.roll(lnr, -1) - np.roll(lnr, 1)) / (2 * width)
        ok = (n >= min_count) & (np.roll(n, 1) >= min_count) & (np.roll(n, -1) >= min_count)
    else:
        dln = np.gradient(lnr, width, edge_order=2)
        ok = n >= min_count
        ok[1:-1] &= (n[:-2] >= min_count) & (n[2:] >= min_count)
    grad = -kT * dln + k * mean_lz
    return np.where(ok, grad, np.nan)


def integrate_gradient(grad, width, periodic):
    """(A (kJ/mol, minimum 0), closure) from A' by the trapezoidal rule over the longest run
    of valid (finite) bins, wrapping round for a periodic CV; other bins are NaN. For a
    periodic CV with every bin valid, the mean of A' (``closure``: ∮A' dz / period, which
    sampling noise makes non-zero) is removed first."""
    g = np.asarray(grad, dtype=float)
    n = len(g)
    valid = np.isfinite(g)
    closure = float(np.mean(g)) if periodic and valid.all() else float("nan")
    A = np.full(n, np.nan)
    if not valid.any():
        return A, closure
    if valid.all():
        g = g - (closure if periodic else 0.0)
        run = list(range(n))
    else:
        start = int(np.flatnonzero(~valid)[0])
        order = list(np.roll(np.arange(n), -start)) if periodic else list(range(n))
        runs, cur = [], []
        for i in order:
            if valid[i]:
                cur.append(i)
            elif cur:
                runs.append(cur)
                cur = []
        if cur:
            runs.append(cur)
        run = max(runs, key=len)
    acc = 0.0
    A[run[0]] = 0.0
    for a, b in zip(run[:-1], run[1:]):
        acc += 0.5 * width * (g[a] + g[b])
        A[b] = acc
    return A - np.nanmin(A), closure
