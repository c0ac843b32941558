"""``physics.scheme=monolithic``: Newton on both fields with the coupled tangent, the
staggered scheme taking over where it gives up. On the small centre-cracked plate of
test_fracture both schemes reach the same path (the same minimisers of the same energy), the
monolithic one solves the increments before the crack jump in 5–9 Newton iterations
(staggered: 5–43) and hands the jump, where the coupled tangent is indefinite, to the
staggered iteration; irreversibility holds exactly either way.

The two plate runs take two minutes of CI time: the comparison is a study (``-m slow``); the
default suite keeps the monolithic Newton's own check
(test_fracture_nonlinear::test_monolithic_newton_meets_the_same_solution) and the refusals."""
import numpy as np
import pytest

TIGHT = "physics.staggered_tol=1e-7"     # the plate: CENTRE_CRACKED_PLATE in conftest.py


@pytest.fixture(scope="module")
def both(tmp_path_factory, run_plate):
    root = tmp_path_factory.mktemp("schemes")
    return (run_plate(root / "mono", TIGHT, "physics.scheme=monolithic"),
            run_plate(root / "stag", TIGHT))


@pytest.mark.slow
def test_both_schemes_follow_the_same_path(both):
    mono, stag = both
    # measured: υ within 3.5e-7, the staggered tolerance's size; reactions alike
    np.testing.assert_allclose(mono["phase_field"].values, stag["phase_field"].values,
                               atol=1e-5)
    np.testing.assert_allclose(mono["reaction"].values, stag["reaction"].values, rtol=1e-4,
                               atol=1e-12)
    np.testing.assert_allclose(mono["elastic_energy"].values, stag["elastic_energy"].values,
                               rtol=1e-4, atol=1e-12)
    assert np.all(np.diff(mono["phase_field"].values, axis=0) <= 0.0)


@pytest.mark.slow
def test_monolithic_newton_solves_the_stable_increments_and_hands_over_the_jump(both):
    mono, stag = both
    m = mono["monolithic_iterations"].values[1:]
    k = mono["staggered_iterations"].values[1:]
    assert np.all(m[:3] > 0) and np.all(k[:3] == 0)       # solved monolithically
    assert m[-1] == 0 and k[-1] > 10                        # the jump: staggered took over
    assert np.all((m > 0) != (k > 0))                       # exactly one scheme each time
    assert np.all(stag["monolithic_iterations"].values == 0)
    # fewer iterations where the staggered scheme is slowest before the jump (7 against 43)
    assert m[3] < stag["staggered_iterations"].values[4]


def test_a_monolithic_split_or_phase_field_alone_is_refused():
    from pointatlas.errors import ConfigError
    from pointatlas_physics.kirchhoff_love_fracture.settings import (FractureSettings,
                                                                     check_fracture_settings)

    with pytest.raises(ConfigError, match="no coupled tangent for physics.split=amor"):
        check_fracture_settings(FractureSettings(length_scale=0.1, scheme="monolithic",
                                                 split="amor"))
    with pytest.raises(ConfigError, match="kinematics=none has no shell"):
        check_fracture_settings(FractureSettings(length_scale=0.1, scheme="monolithic",
                                                 kinematics="none"))
