"""The shell's equilibrium problem on the shared path followers (pointatlas_solvers): small
loads reproduce the linear answer, failures stop cleanly, displacement control gives the
force back as a reaction."""
import numpy as np
import pytest

from pointatlas_physics.kirchhoff_love.analysis import (assemble_loads, assemble_supports,
                                                         displacement_at, solve_linear)
from pointatlas_physics.kirchhoff_love.equilibrium import Equilibrium
from pointatlas_solvers.increment import PathFollowingError, PathSettings
from pointatlas_solvers.path_following import follow_path


@pytest.fixture(scope="module")
def plate(quarter_plate):
    s, m = quarter_plate
    m = solve_linear(m, s)
    return m, s, assemble_loads(m, s), assemble_supports(m, s)


def path_of(m, s, path, F, cons, **kw):
    return follow_path(Equilibrium(m, s, F, cons), path, **kw)


def test_small_load_matches_linear_and_large_load_stiffens(plate):
    m, s, F, cons = plate
    u_lin = displacement_at(m, [0, 0, 0])[0][2]
    small = path_of(m, s, PathSettings(n_increments=1), 1e-3 * F, cons)
    m.nodal_displacement = small[-1].U
    assert displacement_at(m, [0, 0, 0])[0][2] / 1e-3 == pytest.approx(u_lin, rel=1e-3)
    assert small[-1].stable and small[-1].iterations <= 4
    big = path_of(m, s, PathSettings(n_increments=2), F, cons)
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
        path_of(m, s, PathSettings(n_increments=1, max_newton=1, min_step=0.3), F, cons,
                on_increment=kept.append)
    assert all(np.isfinite(k.U).all() for k in kept)


def test_displacement_control_reaction_equals_the_force(plate):
    """Imposing the centre deflection of a force-controlled run gives back that force as the
    reaction of the imposed-displacement support (small load: linear regime)."""
    from dataclasses import replace

    from pointatlas_kit.selector_spec import Selector
    from pointatlas_physics.kirchhoff_love.settings import Support

    m, s, F, cons = plate
    forced = path_of(m, s, PathSettings(n_increments=1), 1e-3 * F, cons)
    m.nodal_displacement = forced[-1].U
    w = displacement_at(m, [0, 0, 0])[0][2]
    centre = Support(kind="displacement", components=[2], value=[0.0, 0.0, float(w)],
                     where=Selector(box=[-0.01, -0.01, -1, 0.01, 0.01, 1], on_boundary=False))
    s2 = replace(s, supports=[*s.supports, centre], loads=[])
    cons2 = assemble_supports(m, s2)
    path = path_of(m, s2, PathSettings(n_increments=2), 0.0 * F, cons2)
    assert [round(i.load_factor, 12) for i in path] == [0.5, 1.0]
    # the centre support pushes with the force the load applied: −(−50 × 1e-3) along z
    assert path[-1].reactions[-1][2] == pytest.approx(1e-3 * F.sum(axis=0)[2], rel=2e-3)
    assert path[0].reactions[-1][2] == pytest.approx(0.5 * path[-1].reactions[-1][2], rel=1e-3)


def test_lbfgs_stage_and_line_search_reach_the_same_equilibrium(plate):
    """The optional first stages of App. E.2 (L-BFGS on Π_ρ, then Newton with Armijo
    backtracking) land on the equilibrium plain Newton finds."""
    m, s, F, cons = plate
    plain = path_of(m, s, PathSettings(n_increments=2), F, cons)
    staged = path_of(m, s, PathSettings(n_increments=2, lbfgs_iterations=30,
                                        line_search=True), F, cons)
    assert [i.load_factor for i in staged] == pytest.approx([0.5, 1.0])
    n = m.points.shape[0]   # real control points (ghosts far from quadrature points are
    #                         barely determined and carry no energy)
    scale = np.abs(plain[-1].U[:n]).max()
    assert np.abs(staged[-1].U[:n] - plain[-1].U[:n]).max() < 2e-5 * scale
    assert staged[-1].energy["total"] == pytest.approx(plain[-1].energy["total"], rel=1e-6)


def test_the_problem_gives_the_path_followers_what_they_ask_for(plate):
    """The members of pointatlas_solvers.equilibrium_problem.EquilibriumProblem."""
    from pointatlas_solvers.equilibrium_problem import EquilibriumProblem

    m, s, F, cons = plate
    eq = Equilibrium(m, s, F, cons)
    members = [k for k in EquilibriumProblem.__annotations__] + [
        k for k in vars(EquilibriumProblem) if not k.startswith("_")]
    assert all(hasattr(eq, k) for k in members), [k for k in members if not hasattr(eq, k)]
    n = m.nodes.shape[0]
    assert eq.F.shape == (3 * n,) and eq.n_components == 3
    assert eq.row_support.shape == (eq.C.shape[0],)
    # the arc length measures the sampled points' DOFs, not the ghosts'
    assert eq.arc_mask.sum() == 3 * m.points.shape[0] and eq.arc_mask[:3].all()
    assert eq.length_scale == pytest.approx(float(np.ptp(m.nodes, axis=0).max()))


def test_a_new_system_takes_over_the_last_factorisation_and_gives_the_same_answer(plate):
    """system() hands the previous system's PARDISO handle on (same pattern: no new
    analysis): the factors are a fresh factorisation's bit for bit, and the old system
    refuses to solve instead of answering with the new matrix's factors."""
    from dataclasses import replace

    from pointatlas.errors import PointatlasError

    pytest.importorskip("pypardiso")
    m, s, F, cons = plate
    s = replace(s, solver="pardiso")
    U = 1e-3 * np.random.default_rng(0).standard_normal(3 * m.nodes.shape[0])
    eq = Equilibrium(m, s, F, cons)
    first = eq.system(0.5 * U)   # (at U = 0 the flat plate's membrane and bending
    #                               blocks are exact zeros, dropped: another pattern)
    second = eq.system(U)
    fresh = Equilibrium(m, s, F, cons).system(U)
    assert second.factorization._solver is not None and first.factorization._solver is None
    b = np.random.default_rng(1).standard_normal(U.size)
    assert np.array_equal(second.inverse(b), fresh.inverse(b))
    assert second.negative_pivots == fresh.negative_pivots
    with pytest.raises(PointatlasError, match="handed on"):
        first.inverse(b)
