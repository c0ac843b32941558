"""symmetry_defect of the fracture study: exact on a hand-made mirror-symmetric cloud, and a
cloud without mirror symmetry is refused rather than interpolated."""
import numpy as np
import pytest
import xarray as xr

from pointatlas.errors import ConfigError, InputError
from pointatlas_studies.fracture_symmetry import check_plane, mirror_index, symmetry_defect

X = np.array([[-1.0, 0, 0], [1, 0, 0], [-2, 1, 0], [2, 1, 0], [0, 3, 0]])


def test_mirror_index_pairs_images_and_keeps_points_on_the_plane():
    np.testing.assert_array_equal(mirror_index(X, [2, 0, 0, 0]), [1, 0, 3, 2, 4])
    np.testing.assert_array_equal(mirror_index(X + [1, 0, 0], [1, 0, 0, 1]), [1, 0, 3, 2, 4])


def test_defect_is_the_relative_l2_difference():
    v = np.array([[1.0, 1, 1, 1, 1], [0.0, 1, 0.5, 0.5, 1]])
    ds = symmetry_defect(xr.Dataset({"position": (("point", "dim"), X),
                                     "phase_field": (("increment", "point"), v)}), [1, 0, 0, 0])
    np.testing.assert_allclose(ds["symmetry_defect_history"].values,
                               [0.0, np.sqrt(2) / np.linalg.norm(v[1])])
    assert float(ds["symmetry_defect"]) == pytest.approx(np.sqrt(2) / np.linalg.norm(v[1]))
    assert float(ds["symmetry_defect_damage"]) == pytest.approx(np.sqrt(2) / np.sqrt(1.5))


def test_a_cloud_without_the_symmetry_and_a_bad_plane_are_refused():
    with pytest.raises(InputError, match="not mirror symmetric"):
        mirror_index(X + [0.1, 0, 0], [1, 0, 0, 0])
    with pytest.raises(ConfigError, match="study.mirror_plane"):
        check_plane([0, 0, 0, 1], "mirror_plane")
