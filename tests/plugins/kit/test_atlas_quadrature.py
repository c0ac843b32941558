import numpy as np
import pytest

from pointatlas.errors import InputError
from pointatlas_kit.atlas_quadrature import AtlasQuadrature


def _arrays(m=3, k=4, n_nodes=20):
    rng = np.random.default_rng(0)
    T = np.zeros((m, 2, 3))
    T[:, 0, 0], T[:, 1, 1] = 1.0, 2.0
    return dict(indptr=np.arange(m + 1) * k, indices=np.tile(np.arange(k), m),
                basis=rng.random((m * k, 6)), weights=np.ones(m), chart=np.zeros(m, int),
                positions=np.zeros((m, 3)), tangents=T, second=np.zeros((m, 2, 2, 3)),
                orientation=-np.ones(m), n_nodes=n_nodes)


def test_geometry_of_the_points():
    q = AtlasQuadrature(**_arrays())
    assert q.order == 2 and q.n_points == 3
    assert np.allclose(q.metric[0], [[1, 0], [0, 4]])
    assert np.allclose(q.inverse_metric[0], [[1, 0], [0, 0.25]])
    assert np.allclose(q.normals, [0, 0, -1])          # the orientation sign applies
    assert q.reference_jet().shape == (3, 5, 3)
    assert np.isclose(q.integrate(np.arange(3.0)), 3.0)
    assert q.interpolation().shape == (3, 20)


def test_bad_arrays_raise():
    a = _arrays()
    with pytest.raises(InputError, match="weights"):
        AtlasQuadrature(**{**a, "weights": np.ones(2)})
    with pytest.raises(InputError, match="indices"):
        AtlasQuadrature(**{**a, "n_nodes": 2})
    with pytest.raises(InputError, match="indptr"):
        AtlasQuadrature(**{**a, "indptr": np.array([0, 4, 8, 13])})
    with pytest.raises(InputError, match="order=2"):
        AtlasQuadrature(**{**a, "second": None}).reference_jet()


def test_atlas_quadrature_of_a_built_atlas_matches_the_atlas():
    """On pyvista's bundled sphere.ply (points made by nobody here): the kit's quadrature
    holds the atlas's points, its weights integrate the area like the atlas does, and the
    normals point outwards (the atlas's one orientation)."""
    import os

    import pyvista

    from pointatlas_kit.atlas_quadrature import atlas_quadrature, node_quadrature

    from ..atlas.test_atlas import make_atlas

    pts = pyvista.read(os.path.join(os.path.dirname(pyvista.examples.__file__),
                                    "sphere.ply")).points.astype(float)
    pts = np.unique(pts, axis=0)
    atlas = make_atlas(allow_failed_patches=True)
    atlas.partition(pts, keep_basis=True)
    atlas.build_charts()
    atlas.build_quadrature(keep_basis=True)
    q = atlas_quadrature(atlas, order=2)
    assert q.n_points == sum(len(c.weights) for c in atlas.quadrature_)
    assert np.isclose(q.weights.sum(), atlas.integrate(lambda p: np.ones(len(p.weights))))
    centre = pts.mean(axis=0)
    assert (np.einsum("mi,mi->m", q.normals, q.positions - centre) > 0).all()
    ones = q.interpolation() @ np.ones(q.n_nodes)
    assert np.allclose(ones, 1.0, atol=1e-8)              # partition of unity of the basis
    qn, rows = node_quadrature(atlas, np.arange(10), order=1)
    assert qn.order == 1 and np.allclose(qn.positions, atlas.points_[np.arange(10)][rows],
                                         atol=1e-6 * np.ptp(pts))
