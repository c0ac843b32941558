"""A point load off the surface is refused with its distance, the nearest surface point and
the spacing; one on the surface gets its force."""
import numpy as np
import pytest

import pointatlas
from pointatlas.errors import InputError
from pointatlas_atlas.atlas import Atlas
from pointatlas_atlas.settings import AtlasSettings
from pointatlas_physics.kirchhoff_love.loads import point_load

MAX_OFFSET = 0.5  # ShellSettings.max_load_offset's default, spacings


@pytest.fixture(scope="module")
def plate():
    """(atlas, points, h) of a flat 4 × 4 plate z = 0 of 100 points (h = 4/9 ... 0.5)."""
    P = pointatlas.load_plugin("sources", "square_plate")(n_points=100, length=4.0).load(
        np.random.default_rng(0)).points
    atlas = Atlas(AtlasSettings(markers_per_patch=100, quadrature_order=2),
                  lambda: pointatlas.load_plugin("embedders", "pca")(n_components=2),
                  lambda: pointatlas.load_plugin("approximants", "lme")(gamma=0.8, tol=1e-8,
                                                                       outside="flag"),
                  lambda: pointatlas.load_plugin("approximants", "shepard")(gamma=4.0, tol=1e-6,
                                                                           outside="flag"))
    atlas.partition(P, P)
    atlas.build_charts()
    return atlas, P, atlas.h_points_


def _vec(v):
    return "[" + ", ".join(f"{c:.6g}" for c in v) + "]"


def test_a_point_ten_spacings_off_the_plate_names_distance_nearest_point_and_spacing(plate):
    atlas, P, h = plate
    i = int(np.argmin(np.linalg.norm(P - [0.3, 0.2, 0.0], axis=1)))  # an interior point
    at = P[i] + [0.0, 0.0, 10 * h]
    with pytest.raises(InputError) as info:
        point_load(atlas, at, [0, 0, -1.0], h, MAX_OFFSET)
    msg = str(info.value)
    assert "inf" not in msg and "\n" not in msg
    assert f"is {10 * h:.3g} off the surface (10 spacings" in msg  # from the nearest point
    assert "projection" in msg and "failed" in msg  # no chart reaches 10 h out
    assert f"nearest sampled point {_vec(P[i])}" in msg
    assert f"spacing h = {h:.3g}" in msg and f"within {MAX_OFFSET * h:.3g}" in msg
    assert f"Fix: move the load point onto the surface, e.g. at: {_vec(P[i])}" in msg


def test_a_point_just_off_the_plate_names_its_projection(plate):
    atlas, P, h = plate
    on = np.array([0.3, 0.2, 0.0])  # between sampled points: the projection is (x, y, 0)
    with pytest.raises(InputError) as info:
        point_load(atlas, on + [0, 0, 2 * h], [0, 0, -1.0], h, MAX_OFFSET)
    msg = str(info.value)
    assert f"is {2 * h:.3g} off the surface (2 spacings" in msg
    assert f"the nearest surface point is {_vec(on)}" in msg and "failed" not in msg
    assert f"spacing h = {h:.3g}" in msg and f"e.g. at: {_vec(on)}" in msg


def test_a_point_within_the_allowed_offset_gets_the_whole_force(plate):
    atlas, P, h = plate
    F, where, dist = point_load(atlas, [0.3, 0.2, 0.4 * h], [1.0, 0, -2.0], h, MAX_OFFSET)
    np.testing.assert_allclose(where, [0.3, 0.2, 0.0], atol=1e-9)
    assert dist == pytest.approx(0.4 * h, rel=1e-9)
    np.testing.assert_allclose(F.sum(axis=0), [1.0, 0, -2.0], atol=1e-12)
