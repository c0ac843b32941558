"""The training set: boundary landmarks of a mesh and the decimation by a cut-off distance."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.spatial.distance import pdist, squareform

from pointatlas.errors import InputError
from pointatlas_reduction.training_set import boundary_nodes, decimate, landmark_columns


def test_boundary_of_a_structured_square_mesh():
    """scikit-fem's refined unit square (built independently): its boundary nodes are those
    with a coordinate at 0 or 1."""
    from skfem import MeshTri

    m = MeshTri.init_symmetric().refined(3)
    p, t = m.p.T, m.t.T
    on_edge = np.flatnonzero(np.isclose(p, 0).any(1) | np.isclose(p, 1).any(1))
    assert np.array_equal(boundary_nodes(t), on_edge)
    bottom = np.flatnonzero(np.isclose(p[:, 1], 0))
    assert np.array_equal(boundary_nodes(t, exclude=bottom), np.setdiff1d(on_edge, bottom))


def test_landmark_columns_pick_the_nodes_coordinates():
    x = np.arange(10 * 2).reshape(10, 2).astype(float)
    cols = landmark_columns(np.array([3, 7]))
    assert np.array_equal(x.ravel()[cols], x[[3, 7]].ravel())


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), dim=st.integers(2, 30),
       cutoff=st.floats(0.05, 1.5))
def test_decimation_is_separated_and_greedy_maximal(seed, dim, cutoff):
    X = np.random.default_rng(seed).normal(size=(300, dim)) * 0.5
    keep = decimate(X, cutoff, n_project=4)
    Dk = squareform(pdist(X[keep]))
    np.fill_diagonal(Dk, np.inf)
    assert Dk.min() >= cutoff                    # any two kept rows at least the cut-off apart
    D = squareform(pdist(X))
    kept = np.zeros(len(X), bool)
    kept[keep] = True
    for i in np.flatnonzero(~kept):              # each dropped row has an earlier kept row near
        earlier = keep[keep < i]
        assert len(earlier) and D[i, earlier].min() < cutoff
    assert keep[0] == 0 and np.all(np.diff(keep) > 0)


def test_decimation_of_a_dense_curve_keeps_spacing():
    s = np.linspace(0, 1, 5001)
    X = np.column_stack([np.cos(2 * np.pi * s), np.sin(2 * np.pi * s), s])
    keep = decimate(X, 0.05)
    steps = np.linalg.norm(np.diff(X[keep], axis=0), axis=1)
    assert steps.min() >= 0.05 and steps.max() < 0.05 + 2e-3


def test_zero_cutoff_keeps_all_and_bad_cutoff_refused():
    X = np.random.default_rng(0).normal(size=(20, 3))
    assert np.array_equal(decimate(X, 0.0), np.arange(20))
    with pytest.raises(InputError, match="cutoff"):
        decimate(X, float("nan"))
