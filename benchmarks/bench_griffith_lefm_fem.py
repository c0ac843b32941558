"""Benchmark: the LEFM critical stress of the fracture_griffith specimen, by finite elements
(issue 18), to tell the phase field's error from the reference formula's.

The experiment compares its peak remote stress with Griffith's σ_c and Feddersen's width
correction, σ_c = √(E G_c/(π a)) √(cos(π a/W)), a formula for an infinitely long strip under
remote stress. The specimen is a square W × W plate pulled by rigid grips (u_y uniform, u_x
free on y = ±W/2). Here its exact LEFM critical stress is computed with scikit-fem (an
independent code: quadratic P2 triangles, plane stress) on the same quarter
x, y ∈ [0, W/2]: u_x = 0 on x = 0, u_y = 0 on the ligament a ≤ x ≤ W/2 of y = 0 (the crack
faces 0 ≤ x < a free), u_y = δ on y = W/2.

With k(a) the quarter's stiffness per unit thickness (its stored energy ½ h k δ², h the
thickness), a tip advance da dissipates G_c h da/2 in the quarter (the full plate's crack
2a grows by 2 da at its two tips), so under displacement control the crack runs at
δ_c² = G_c / (−k'(a)) and σ_c = k(a) δ_c / (W/2) (E = 1, G_c = 1e-3, ν = 0.3, a = W/4 as in
experiments/fracture_griffith.yaml). k' by the central difference of three crack lengths
a, a ± da on one tensor mesh graded geometrically (ratio 1.15) toward the tip, which holds
nodes at all three tips; the smallest cell hmin is halved to show convergence.

Usage: .venv/bin/pip install '.[bench]' && .venv/bin/python benchmarks/bench_griffith_lefm_fem.py
Measured (2026-12-03): σ_c = 0.030514, 0.030521, 0.030525, 0.030436 for hmin = 4e-3 … 5e-4
(da = 4 hmin), +1.4 … +1.7 % against Feddersen's 0.030005.
"""
from __future__ import annotations

import numpy as np

E, NU, GC, A, W = 1.0, 0.3, 1e-3, 0.25, 1.0
HALF = W / 2
LAM = E * NU / (1 - NU ** 2)        # plane-stress λ* = 2λμ/(λ + 2μ)
MU = E / (2 * (1 + NU))


def graded_axis(centre: float, lo: float, hi: float, hmin: float, ratio: float = 1.15):
    """Nodes on [lo, hi] with cells growing geometrically (``ratio``) away from ``centre``."""
    def side(length):
        if length <= 0:
            return np.zeros(1)
        s, h = [0.0], hmin
        while s[-1] < length:
            s.append(s[-1] + h)
            h *= ratio
        s = np.asarray(s)
        return s * (length / s[-1])
    nodes = np.concatenate([centre - side(centre - lo)[::-1], centre + side(hi - centre)[1:]])
    return np.unique(np.round(nodes, 14))


def stiffness(basis, K, tip: float) -> float:
    """k (per unit thickness) of the quarter with its crack tip at x = ``tip``: δ = 1."""
    from skfem import condense, solve

    lig = basis.get_dofs(lambda p: np.isclose(p[1], 0.0) & (p[0] >= tip - 1e-12))
    top = basis.get_dofs(lambda p: np.isclose(p[1], HALF))
    left = basis.get_dofs(lambda p: np.isclose(p[0], 0.0))
    fixed = np.concatenate([left.all(["u^1"]), lig.all(["u^2"]), top.all(["u^2"])])
    x = np.zeros(basis.N)
    x[top.all(["u^2"])] = 1.0
    u = solve(*condense(K, np.zeros(basis.N), x=x, D=fixed))
    return float(u @ K @ u)            # 2 × stored energy per thickness at δ = 1 = k


def critical_stress(hmin: float):
    from skfem import Basis, ElementTriP2, ElementVector, MeshTri, asm
    from skfem.models.elasticity import linear_elasticity

    da = 4 * hmin
    x = np.unique(np.concatenate([graded_axis(A, 0.0, HALF, hmin), [A - da, A + da]]))
    y = graded_axis(0.0, 0.0, HALF, hmin)
    basis = Basis(MeshTri.init_tensor(x, y), ElementVector(ElementTriP2()))
    K = asm(linear_elasticity(LAM, MU), basis)
    k_minus, k0, k_plus = (stiffness(basis, K, t) for t in (A - da, A, A + da))
    dk = (k_plus - k_minus) / (2 * da)
    delta_c = np.sqrt(GC / -dk)
    return basis.N, k0, dk, k0 * delta_c / HALF


def main():
    feddersen = np.sqrt(E * GC / (np.pi * A)) * np.sqrt(np.cos(np.pi * A / W))
    print(f"Feddersen (infinite strip): sigma_c = {feddersen:.6f}")
    for hmin in (4e-3, 2e-3, 1e-3, 5e-4):
        n, k0, dk, s = critical_stress(hmin)
        print(f"hmin {hmin:g}: {n} dofs, k {k0:.6f}, dk/da {dk:.6f}, sigma_c {s:.6f} "
              f"({s / feddersen - 1:+.2%} against Feddersen)")


if __name__ == "__main__":
    main()
