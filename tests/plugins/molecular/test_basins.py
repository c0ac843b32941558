"""Basin boxes, torus distances, basin minima and the map of a CV grid onto (φ, ψ)."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from pointatlas_molecular.basins import (angular_distance, basin_minimum, grid_dihedrals,
                                         in_basin)


@settings(max_examples=50, deadline=None)
@given(st.floats(-180, 180), st.floats(-180, 180), st.floats(-180, 180), st.floats(-180, 180))
def test_torus_distance_is_symmetric_and_wraps(a, b, c, d):
    x, y = (a, b), (c, d)
    assert np.isclose(angular_distance(x, y), angular_distance(y, x))
    assert angular_distance(x, y) <= np.sqrt(2) * 180 + 1e-9
    assert np.isclose(angular_distance(x, (c + 360, d - 360)), angular_distance(x, y))


def test_c5_wrapping_through_180_is_not_the_c7ax_basin():
    assert not in_basin(175.0, "C7ax") and in_basin(70.0, "C7ax")
    assert in_basin(-80.0, "C7eq") and not in_basin(-150.0, "C7eq")


def test_basin_minimum_picks_the_lowest_cell_inside_the_basin():
    phi = np.array([-150.0, -80, -60, 60, 170])
    psi = np.array([160.0, 70, -40, -60, 160])
    A = np.array([0.0, 1.0, 3.0, 9.0, np.nan])
    assert basin_minimum(A, phi, psi, "C7eq") == ((-80.0, 70.0), 1.0)
    assert basin_minimum(A, phi, psi, "C7ax") == ((60.0, -60.0), 9.0)
    p, a = basin_minimum(A[:3], phi[:3], psi[:3], "C7ax")
    assert np.isnan(p[0]) and np.isnan(a)


class _RotatingChain:
    """A 'manifold' of 4-atom chains whose dihedral is q_0 (rad); undefined for q_0 > 2."""

    def contains(self, q):
        return q[0] <= 2.0

    def evaluate(self, q):
        t = q[0, 0]
        x = np.array([[0, 1, 0], [0, 0, 0], [1, 0, 0], [1, np.cos(t), np.sin(t)]])
        return x.reshape(1, -1)


def test_grid_dihedrals_of_a_known_family():
    centres = [np.array([-1.0, 0.5, 2.5]), np.array([0.0, 1.0])]
    out = grid_dihedrals(_RotatingChain(), centres, [(0, 1, 2, 3)])
    assert out.shape == (3, 2, 1)
    assert np.all(np.isnan(out[2]))
    assert np.allclose(out[:2, 0, 0], np.degrees([-1.0, 0.5]))   # the dihedral is q_0
    assert np.allclose(out[:2, 0, 0], out[:2, 1, 0])                # q_1 plays no part
