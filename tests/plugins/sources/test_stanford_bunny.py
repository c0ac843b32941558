"""The stanford_bunny source: pymeshlab's bunny.obj read as points, checked against pyvista's
independent reading of the same file."""
import sys

import numpy as np
import pytest

from pointatlas.errors import ConfigError, InputError

pytest.importorskip("pymeshlab")
pv = pytest.importorskip("pyvista")

from pointatlas_sources.stanford_bunny import (  # noqa: E402
    RAW_HEIGHT, StanfordBunny, bunny_path, closed_euler_characteristic, distinct_rows, read_obj)


@pytest.fixture(scope="module")
def mesh():
    return pv.read(str(bunny_path()))


def test_reads_every_vertex_with_the_mesh_references(mesh):
    cloud = StanfordBunny().load(np.random.default_rng(0))
    assert cloud.points.shape == (28088, 3) and cloud.intrinsic_dim == 2
    np.testing.assert_array_equal(cloud.points, np.asarray(mesh.points, dtype=np.float64))
    assert cloud.exact["area"] == pytest.approx(mesh.area, rel=1e-12)
    assert cloud.exact["area"] == pytest.approx(0.92269, abs=5e-6)
    assert cloud.exact["total_gaussian_curvature"] == pytest.approx(4 * np.pi)
    assert cloud.exact["euler_characteristic"] == 2 and cloud.exact["genus"] == 0
    assert cloud.info == {"points_in_source": 28088, "points_used": 28088,
                          "duplicate_vertices_dropped": 0, "scale": 1.0}
    assert np.ptp(cloud.points[:, 1]) == pytest.approx(RAW_HEIGHT, abs=1e-6)


def test_file_is_closed_genus_zero_by_pyvista(mesh):
    edges = mesh.extract_feature_edges(boundary_edges=True, non_manifold_edges=True,
                                       feature_edges=False, manifold_edges=False)
    assert edges.n_cells == 0
    V, F = read_obj(bunny_path())
    assert len(F) == mesh.n_cells == 56172 and closed_euler_characteristic(F, len(V)) == 2


def test_scale_multiplies_lengths_and_the_area_reference(mesh):
    s = 1.5 / RAW_HEIGHT
    cloud = StanfordBunny(scale=s).load(np.random.default_rng(0))
    assert np.ptp(cloud.points[:, 1]) == pytest.approx(1.5, rel=1e-9)
    assert cloud.exact["area"] == pytest.approx(mesh.area * s * s, rel=1e-12)


def test_subsample_is_farthest_point_and_deterministic_by_seed(caplog):
    with caplog.at_level("INFO", logger="pointatlas.sources"):
        a = StanfordBunny(n_points=500).load(np.random.default_rng(3))
    b = StanfordBunny(n_points=500).load(np.random.default_rng(3))
    c = StanfordBunny(n_points=500).load(np.random.default_rng(4))
    assert a.points.shape == (500, 3) and len(np.unique(a.points, axis=0)) == 500
    np.testing.assert_array_equal(a.points, b.points)
    assert not np.array_equal(a.points, c.points)
    assert a.info["points_used"] == 500 and a.info["points_in_source"] == 28088
    assert "using 500 of 28088 vertices" in caplog.text
    # quasi-uniform: no two kept points closer than half the spread of a uniform 500-set
    from scipy.spatial import cKDTree

    d = cKDTree(a.points).query(a.points, k=2)[0][:, 1]
    assert d.min() > 0.5 * np.median(d)
    # a subset of the vertices
    full = {tuple(p) for p in StanfordBunny().load(np.random.default_rng(0)).points}
    assert all(tuple(p) in full for p in a.points)


def test_duplicates_are_dropped_and_counted():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 0], [0, 1, 0], [1, 0, 0.0]])
    kept, dropped = distinct_rows(V)
    assert dropped == 2
    np.testing.assert_array_equal(kept, V[[0, 1, 3]])


def test_missing_pymeshlab_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "pymeshlab", None)   # import pymeshlab -> ImportError
    with pytest.raises(ConfigError, match=r"pip install 'pointatlas\[meshes\]'") as info:
        StanfordBunny().check_config()
    assert "\n" not in str(info.value) and "pymeshlab" in str(info.value)
    with pytest.raises(ConfigError, match=r"pointatlas\[meshes\]"):
        StanfordBunny().load(np.random.default_rng(0))


@pytest.mark.parametrize("bad", [{"scale": 0.0}, {"scale": float("nan")}, {"n_points": 2},
                                 {"n_points": 3.5}])
def test_bad_settings_are_refused(bad):
    with pytest.raises(ConfigError, match=next(iter(bad))):
        StanfordBunny(**bad).check_config()


def test_an_open_mesh_is_refused(tmp_path, monkeypatch):
    path = tmp_path / "tests" / "sample_meshes" / "bunny.obj"
    path.parent.mkdir(parents=True)
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    import pointatlas_sources.stanford_bunny as module

    monkeypatch.setattr(module, "bunny_path", lambda: path)
    with pytest.raises(InputError, match="not the closed genus-0 bunny"):
        StanfordBunny().load(np.random.default_rng(0))
