"""The staggered increment's jump floor: an iterate whose elastic energy falls below it stops
the increment at once (CrackJumped), and a floor the iterates stay above leaves the converged
increment exactly as without it."""
import numpy as np
import pytest


@pytest.fixture(scope="module")
def plate(tmp_path_factory):
    """fracture_griffith's traction-free quarter plate on 121 points (κ̄ = 2 spacings) and its
    converged increment at t = 0.2 (the crack has not run yet)."""
    from pointatlas.testing import composed_context
    from pointatlas_atlas.plugin import study_atlas_settings

    ctx = composed_context(tmp_path_factory.mktemp("plate"), [
        "experiment=fracture_griffith", "source.n_points=121", "physics.length_scale=0.1"])
    study, physics = ctx.plugin("study"), ctx.plugin("physics")
    atlas = study_atlas_settings(ctx, study)
    atlas.check()
    cloud = ctx.plugin("source").load(ctx.rng("source"))
    problem = physics.fracture_path(ctx, cloud=cloud, atlas_settings=atlas)
    return problem, problem.increment(problem.initial_state(), 0.2)


def test_an_iterate_below_the_jump_floor_stops_the_increment(plate):
    from pointatlas_physics.kirchhoff_love_fracture.staggered import CrackJumped

    problem, before = plate
    full = problem.increment(before, 0.4)
    # the crack runs through the ligament in this step: the elastic energy falls to a
    # quarter (measured 8.28e-6 -> 1.88e-6 in 20 staggered iterations)
    assert full.energy["elastic"] < 0.5 * before.energy["elastic"]
    floor = 0.9 * before.energy["elastic"]
    with pytest.raises(CrackJumped, match="the crack jumps") as info:
        problem.increment(before, 0.4, jump_floor=floor)
    assert info.value.elastic < floor
    assert info.value.iteration < full.staggered_iterations

    # a floor below every iterate: the same increment, to the last bit
    same = problem.increment(before, 0.4, jump_floor=0.5 * full.energy["elastic"])
    np.testing.assert_array_equal(same.phase_nodal, full.phase_nodal)
    np.testing.assert_array_equal(same.displacement_nodal, full.displacement_nodal)
    assert same.staggered_iterations == full.staggered_iterations
