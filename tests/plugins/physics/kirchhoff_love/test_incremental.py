"""Force-controlled load path: small loads reproduce the linear answer; failures stop cleanly."""
import numpy as np
import pytest

from pointatlas_physics.kirchhoff_love.analysis import (assemble_loads, assemble_supports,
                                                         displacement_at, solve_linear)
from pointatlas_physics.kirchhoff_love.incremental import (PathFollowingError, PathSettings,
                                                            follow_path)



@pytest.fixture(scope="module")
def plate(quarter_plate):
    s, m = quarter_plate
    m = solve_linear(m, s)
    return m, s, assemble_loads(m, s), assemble_supports(m, s)


def test_small_load_matches_linear_and_large_load_stiffens(plate):
    m, s, F, cons = plate
    u_lin = displacement_at(m, [0, 0, 0])[0][2]
    small = follow_path(m, s, PathSettings(n_increments=1), 1e-3 * F, cons)
    m.nodal_displacement = small[-1].U
    assert displacement_at(m, [0, 0, 0])[0][2] / 1e-3 == pytest.approx(u_lin, rel=1e-3)
    assert small[-1].stable and small[-1].iterations <= 4
    big = follow_path(m, s, PathSettings(n_increments=2), F, cons)
    m.nodal_displacement = big[-1].U
    w = displacement_at(m, [0, 0, 0])[0][2]
    # w ≈ 12 thicknesses in the linear answer: membrane action must stiffen the plate
    assert 0.1 * abs(u_lin) < abs(w) < 0.5 * abs(u_lin)
    assert [round(i.load_factor, 12) for i in big] == [0.5, 1.0]
    assert big[-1].energy["membrane"] > 0 and big[-1].energy["bending"] > 0


def test_unconvergeable_path_stops_with_the_remedies(plate):
    m, s, F, cons = plate
    kept = []
    with pytest.raises(PathFollowingError, match="arc-length"):
        follow_path(m, s, PathSettings(n_increments=1, max_newton=1, min_step=0.3), F, cons,
                    on_increment=kept.append)
    assert all(np.isfinite(k.U).all() for k in kept)


def test_displacement_control_reaction_equals_the_force(plate):
    """Imposing the centre deflection of a force-controlled run gives back that force as the
    reaction of the imposed-displacement support (small load: linear regime)."""
    from dataclasses import replace

    from pointatlas_physics.kirchhoff_love.selector_spec import Selector
    from pointatlas_physics.kirchhoff_love.settings import Support

    m, s, F, cons = plate
    forced = follow_path(m, s, PathSettings(n_increments=1), 1e-3 * F, cons)
    m.nodal_displacement = forced[-1].U
    w = displacement_at(m, [0, 0, 0])[0][2]
    centre = Support(kind="displacement", components=[2], value=[0.0, 0.0, float(w)],
                     where=Selector(box=[-0.01, -0.01, -1, 0.01, 0.01, 1], on_boundary=False))
    s2 = replace(s, supports=[*s.supports, centre], loads=[])
    cons2 = assemble_supports(m, s2)
    path = follow_path(m, s2, PathSettings(n_increments=2), 0.0 * F, cons2)
    assert [round(i.load_factor, 12) for i in path] == [0.5, 1.0]
    # the centre support pushes with the force the load applied: −(−50 × 1e-3) along z
    assert path[-1].reactions[-1][2] == pytest.approx(1e-3 * F.sum(axis=0)[2], rel=2e-3)
    assert path[0].reactions[-1][2] == pytest.approx(0.5 * path[-1].reactions[-1][2], rel=1e-3)


def test_lbfgs_stage_and_line_search_reach_the_same_equilibrium(plate):
    """The optional first stages of App. E.2 (L-BFGS on Π_ρ, then Newton with Armijo
    backtracking) land on the equilibrium plain Newton finds."""
    m, s, F, cons = plate
    plain = follow_path(m, s, PathSettings(n_increments=2), F, cons)
    staged = follow_path(m, s, PathSettings(n_increments=2, lbfgs_iterations=30,
                                            line_search=True), F, cons)
    assert [i.load_factor for i in staged] == pytest.approx([0.5, 1.0])
    n = m.points.shape[0]   # real control points (ghosts far from quadrature points are
    #                         barely determined and carry no energy)
    scale = np.abs(plain[-1].U[:n]).max()
    assert np.abs(staged[-1].U[:n] - plain[-1].U[:n]).max() < 2e-5 * scale
    assert staged[-1].energy["total"] == pytest.approx(plain[-1].energy["total"], rel=1e-6)


def test_line_search_backtracks_on_an_energy_increase():
    """A step that raises the out-of-balance force and the energy is shortened (Armijo)."""
    from pointatlas_physics.kirchhoff_love.incremental import _line_search

    class Quartic:  # W = u⁴/4 on one free DOF: Newton from u = 1 overshoots nothing, but a
        C = np.zeros((0, 1))  # step of 3 (too long) raises W and |R|
        g = np.zeros(0)
        F = np.zeros(1)
        rho = 0.0

        def residual(self, U, mu, lam):
            return U**3, float(U[0] ** 4 / 4)

        def merit(self, W, U, mu, lam):
            return W

    from scipy.sparse import csr_matrix

    eq = Quartic()
    eq.C = csr_matrix((0, 1))
    U, dU = np.array([1.0]), np.array([-3.0])
    R, W = eq.residual(U, None, 0)
    R_new, W_new = eq.residual(U + dU, None, 0)
    alpha, R_a, W_a = _line_search(eq, U, np.zeros(0), np.zeros(0), 0.0, dU, R, W, R_new, W_new)
    assert alpha < 1 and W_a < W and R_a[0] == pytest.approx((1 - 3 * alpha) ** 3)
