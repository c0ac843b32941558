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
