"""The stand-in column, mesh files and clamp selectors."""
import numpy as np
import pytest

from pointatlas.errors import ConfigError, InputError
from pointatlas_physics.neo_hookean_2d.mesh import (clamped_nodes, read_mesh,
                                                    tapered_column)


def test_the_thesis_size_column():
    m = tapered_column()                                  # 1.5 × (0.24 → 0.08), ≈ 9 428 triangles
    assert (m.n_triangles, m.n_nodes) == (9416, 4945)
    assert np.all(m.areas > 0)
    assert m.areas.sum() == pytest.approx(1.5 * 0.16, rel=1e-12)
    # mirror symmetric about x = 0: the reflected mesh has the same triangles
    mirrored = m.nodes * [-1, 1]
    def key(P):
        return {tuple(np.round(np.sort(P[t], axis=0).ravel(), 9)) for t in m.triangles}

    assert key(mirrored) == key(m.nodes)


def test_the_target_size_is_followed():
    for n in (50, 400, 3000):
        assert abs(tapered_column(n_triangles=n).n_triangles - n) < 0.2 * n


def test_a_vtu_and_a_msh_file_are_read(tmp_path):
    meshio = pytest.importorskip("meshio")
    m = tapered_column(n_triangles=60)
    tri = m.triangles.copy()
    tri[::2] = tri[::2, [0, 2, 1]]                        # clockwise ones get turned round
    pts = np.column_stack([m.nodes, np.zeros(m.n_nodes)])
    pts = np.vstack([pts, [[9.0, 9.0, 0.0]]])             # a point no triangle uses is dropped
    out = meshio.Mesh(pts, [("triangle", tri), ("line", np.array([[0, 1]]))])
    for name in ("body.vtu", "body.msh"):
        kw = {"file_format": "gmsh22", "binary": False} if name.endswith("msh") else {}
        meshio.write(tmp_path / name, out, **kw)
        r = read_mesh(tmp_path / name)
        assert r.n_nodes == m.n_nodes and r.n_triangles == m.n_triangles
        assert np.all(r.areas > 0)
        assert r.areas.sum() == pytest.approx(m.areas.sum())


def test_a_vtu_file_is_read_without_meshio(tmp_path, monkeypatch):
    import sys

    import pyvista

    m = tapered_column(n_triangles=40)
    cells = np.column_stack([np.full(m.n_triangles, 3), m.triangles]).ravel()
    grid = pyvista.UnstructuredGrid(cells, np.full(m.n_triangles, pyvista.CellType.TRIANGLE),
                                    np.column_stack([m.nodes, np.zeros(m.n_nodes)]))
    grid.save(tmp_path / "body.vtu")
    monkeypatch.setitem(sys.modules, "meshio", None)      # import meshio raises ImportError
    r = read_mesh(tmp_path / "body.vtu")
    assert r.n_triangles == m.n_triangles and np.all(r.areas > 0)


def test_an_unreadable_mesh_file_is_one_line(tmp_path):
    bad = tmp_path / "body.msh"
    bad.write_text("this is not a mesh\n")
    for path in (bad, tmp_path / "missing.vtu"):
        with pytest.raises(InputError, match=r"physics.mesh_file=.* cannot be read") as err:
            read_mesh(path)
        assert "\n" not in str(err.value)


def test_a_file_without_triangles_is_refused(tmp_path):
    meshio = pytest.importorskip("meshio")
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    meshio.write(tmp_path / "quads.vtu", meshio.Mesh(pts, [("quad", np.array([[0, 1, 2, 3]]))]))
    with pytest.raises(InputError, match="holds no linear triangles"):
        read_mesh(tmp_path / "quads.vtu")


def test_clamp_selectors():
    m = tapered_column(n_triangles=200)
    bottom = clamped_nodes(m.nodes, "bottom")
    assert np.all(m.nodes[bottom, 1] == 0) and bottom.sum() == np.sum(m.nodes[:, 1] == 0)
    assert np.array_equal(clamped_nodes(m.nodes, {"y_below": 1e-9}), bottom)
    box = clamped_nodes(m.nodes, {"box": [-1, -1, 0.0, 0.2]})
    assert box.sum() > 0 and np.all(m.nodes[box, 0] <= 0) and np.all(m.nodes[box, 1] <= 0.2)


def test_a_clamp_that_selects_no_node_is_one_line():
    m = tapered_column(n_triangles=200)
    with pytest.raises(InputError, match=r"physics.clamp=\{'y_below': -1.0\} selects 0 "
                                         r"node\(s\) .*physics.clamp=bottom"):
        clamped_nodes(m.nodes, {"y_below": -1.0})
    with pytest.raises(InputError, match="selects every node"):
        clamped_nodes(m.nodes, {"y_below": 10.0})


@pytest.mark.parametrize("clamp", ["top", {"below": 1}, {"box": [0, 0, 1]},
                                   {"box": [1, 0, 0, 1]}, {"y_below": "low"}, 3])
def test_a_malformed_clamp_is_a_config_error(clamp):
    with pytest.raises(ConfigError, match="physics.clamp="):
        clamped_nodes(tapered_column(n_triangles=50).nodes, clamp)
