"""The shell's ParaView files: shell.vtp holds a triangulated surface (every point in a
triangle, no degenerate triangle, none across a hole), the displacement arrays of the solved
model with their units; the triangles of the atlas's charts close a sphere and leave the
hole of a hemisphere open (areas within 2 %); .pvd collections refuse what ParaView could not
animate."""
import numpy as np
import pytest

import pointatlas
from pointatlas.errors import InputError
from pointatlas_atlas.settings import AtlasSettings
from pointatlas_kit.paraview import Array, SnapshotSeries, write_pvd, write_vtp
from pointatlas_kit.surface_model import build_surface_model
from pointatlas_kit.surface_mesh import surface_triangles


def _edges(tri):
    e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    return np.unique(e, axis=0, return_counts=True)


def _areas(X, tri):
    n = np.cross(X[tri[:, 1]] - X[tri[:, 0]], X[tri[:, 2]] - X[tri[:, 0]])
    return 0.5 * np.linalg.norm(n, axis=1), n


def _polys(mesh):
    """(T, 3) triangles of a PolyData read back (its polys only)."""
    faces = np.asarray(mesh.GetPolys().GetConnectivityArray())
    offsets = np.diff(np.asarray(mesh.GetPolys().GetOffsetsArray()))
    assert np.all(offsets == 3), "only triangles"
    return faces.reshape(-1, 3)


def _surface(source, ghost_layers=2, **kw):
    cloud = pointatlas.load_plugin("sources", source)(**kw).load(np.random.default_rng(0))
    return build_surface_model(
        cloud, AtlasSettings(markers_per_patch=100, quadrature_order=2),
        make_embedder=lambda: pointatlas.load_plugin("embedders", "pca")(n_components=2),
        make_lme=lambda: pointatlas.load_plugin("approximants", "lme")(
            gamma=0.8, tol=1e-8, outside="flag"),
        make_pu=lambda: pointatlas.load_plugin("approximants", "shepard")(
            gamma=4.0, tol=1e-6, outside="flag"), order=1, ghost_layers=ghost_layers)


def test_shell_vtp_is_a_surface_with_the_results_and_their_units(quarter_plate, tmp_path):
    import pyvista as pv

    from pointatlas_physics.kirchhoff_love.analysis import solve_linear
    from pointatlas_physics.kirchhoff_love.results import field_dataset, write_vtp as shell_vtp

    s, model = quarter_plate
    model = solve_linear(model, s)
    ds = field_dataset(model)
    path = shell_vtp(model, tmp_path / "shell.vtp", magnification=250.0,
                     units_system="mm_N_s")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["shell.vtp"]   # no leftover
    mesh = pv.read(path)
    X = ds["position"].values
    np.testing.assert_array_equal(mesh.points, X)        # the reference configuration
    tri = _polys(mesh)
    assert mesh.GetNumberOfVerts() == 0 and len(tri) > 0
    # the quarter plate [0, 5]² of 14 × 14 points: 2 · 13² triangles, each point in one,
    # their area the plate's (25) to rounding, none degenerate, one boundary loop (χ = 1)
    assert len(tri) == 2 * 13 ** 2
    assert np.unique(tri).size == len(X)
    area, _ = _areas(X, tri)
    assert area.sum() == pytest.approx(25.0, rel=1e-12)
    assert area.min() > 0.1 * area.max()
    edges, count = _edges(tri)
    assert count.max() == 2 and len(np.unique(tri)) - len(edges) + len(tri) == 1
    u = ds["displacement_field"].values
    np.testing.assert_array_equal(mesh.point_data["u"], u)
    np.testing.assert_allclose(mesh.point_data["u_magnitude"], np.linalg.norm(u, axis=1),
                               rtol=1e-15)
    assert mesh.point_data["u_magnitude"].max() == pytest.approx(float(ds["max_displacement"]))
    np.testing.assert_allclose(mesh.point_data["deformed"], X + 250.0 * u, rtol=1e-15)
    np.testing.assert_array_equal(mesh.point_data["on_boundary"], ds["on_boundary"].values)
    f = mesh.field_data   # the units as results.nc of a run in mm_N_s would have them
    assert f["u_quantity"][0] == ds["displacement_field"].attrs["units"] == "length"
    assert f["u_units"][0] == "mm" and f["units_system"][0] == "mm_N_s"
    assert f["u_magnitude_units"][0] == "mm" and f["deformed_units"][0] == "mm"
    assert f["on_boundary_units"][0] == "1" and f["magnification_units"][0] == "1"
    assert "on_boundary_quantity" not in f.keys()
    assert f["magnification"][0] == 250.0
    assert "displacement" in f["u_long_name"][0]
    # ParaView's Warp By Vector with u at the magnification gives 'deformed'
    warped = mesh.warp_by_vector("u", factor=float(f["magnification"][0]))
    np.testing.assert_allclose(warped.points, mesh.point_data["deformed"], atol=1e-12)


HEMISPHERE = dict(n_points=400, model="full", hole_angle_deg=18.0)


@pytest.mark.parametrize("source, kw, area, chi", [
    # the full open hemisphere R = 10 with its 18° hole: an annulus, 2πR² cos 18°, with the
    # shells' two ghost layers and with none (nothing in the hole then: the boundary
    # points' empty gaps keep it open)
    ("hemisphere", HEMISPHERE, 2 * np.pi * 100 * np.cos(np.radians(18.0)), 0),
    ("hemisphere", {**HEMISPHERE, "ghost_layers": 0},
     2 * np.pi * 100 * np.cos(np.radians(18.0)), 0),
    ("sphere", dict(n_points=400), 4 * np.pi, 2)])          # closed, the unit sphere
def test_chart_triangles_cover_the_surface_once(source, kw, area, chi):
    m = _surface(source, **kw)
    X = m.points
    tri = surface_triangles(m.atlas, len(X))
    assert tri.dtype == np.int64 and tri.min() >= 0 and tri.max() < len(X)
    assert np.unique(tri).size == len(X)                    # every point in a triangle
    assert len(np.unique(np.sort(tri, axis=1), axis=0)) == len(tri)   # each once
    a, normal = _areas(X, tri)
    assert a.min() > 1e-3 * a.max()                         # no degenerate triangle
    # measured: the chords 0.27 % (hemisphere, 2 charts) and 0.78 % (sphere, 8 charts) short
    # of the exact area; triangles across the hole would add up to its 5 %, an overlap or a
    # gap between charts as much as its size
    assert a.sum() == pytest.approx(area, rel=0.02) and a.sum() < area
    edges, count = _edges(tri)
    assert count.max() == 2                                 # a manifold
    assert len(np.unique(tri)) - len(edges) + len(tri) == chi   # Euler characteristic
    open_edges = edges[count == 1]
    if chi == 2:
        assert len(open_edges) == 0
        # the atlas's orientation (outward on a closed surface) for every triangle
        assert np.all(np.einsum("ij,ij->i", normal, X[tri].mean(axis=1)) > 0)
    else:   # the open edges run along the equator and the hole's rim, on boundary points
        assert m.boundary[open_edges].all()
        r = np.hypot(X[open_edges, 0], X[open_edges, 1])
        hole = 10 * np.sin(np.radians(18.0))
        assert np.all(np.isclose(r, 10.0, rtol=1e-6) | np.isclose(r, hole, rtol=1e-6))


def test_a_vtp_point_in_no_triangle_is_a_vertex_and_bad_input_is_refused(tmp_path):
    import pyvista as pv

    X = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 5, 0]])
    path = write_vtp(tmp_path / "a.vtp", X, np.array([[0, 1, 2]]),
                     {"w": Array(np.arange(4.0), "energy/length²", "a density")},
                     {"load": Array(2.5, "force", "the load")})
    mesh = pv.read(path)
    assert mesh.GetNumberOfPolys() == 1 and mesh.GetNumberOfVerts() == 1
    assert mesh.field_data["w_units"][0] == "J m-2"                # SI, as results.nc
    assert mesh.field_data["w_quantity"][0] == "energy/length²"    # UTF-8 kept
    assert mesh.field_data["load"][0] == 2.5 and mesh.field_data["load_units"][0] == "N"
    with pytest.raises(InputError, match="units_system = 'cgs' is unknown"):
        write_vtp(tmp_path / "b.vtp", X, np.array([[0, 1, 2]]), {}, units_system="cgs")
    with pytest.raises(InputError, match="indices into its 4 points"):
        write_vtp(tmp_path / "b.vtp", X, np.array([[0, 1, 4]]), {})
    with pytest.raises(InputError, match=r"point array 'w' has shape \(3,\)"):
        write_vtp(tmp_path / "b.vtp", X, np.zeros((0, 3), int),
                  {"w": Array(np.zeros(3), "1", "w")})
    assert not (tmp_path / "b.vtp").exists()


def test_a_pvd_lists_its_steps_relative_to_itself_in_time_order(tmp_path):
    import xml.etree.ElementTree as ET

    import pyvista as pv

    X = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    series = SnapshotSeries(tmp_path / "path.pvd", tmp_path / "snapshots")
    times = [0.0, 0.125, 0.375]
    for k, t in enumerate(times):
        write_vtp(series.path(k), X, np.array([[0, 1, 2]]),
                  {"u": Array(np.full((3, 3), t), "length", "u")})
    series.publish(times)
    root = ET.parse(tmp_path / "path.pvd").getroot()
    assert root.get("type") == "Collection"
    steps = root.find("Collection").findall("DataSet")
    assert [s.get("file") for s in steps] == [f"snapshots/increment_{k:04d}.vtp"
                                              for k in range(3)]
    assert [float(s.get("timestep")) for s in steps] == times
    reader = pv.get_reader(str(tmp_path / "path.pvd"))
    assert reader.time_values == times
    reader.set_active_time_value(0.375)
    np.testing.assert_array_equal(reader.read()[0].point_data["u"], np.full((3, 3), 0.375))
    with pytest.raises(InputError, match="increase strictly"):
        series.publish([0.0, 0.5, 0.5])
    with pytest.raises(InputError, match="increment_0003.vtp, which does not exist"):
        series.publish([0.0, 1.0, 2.0, 3.0])
    with pytest.raises(InputError, match="must end in .pvd"):
        write_pvd(tmp_path / "path.xml", [])
    # the refused rewrites left the collection as it was
    assert len(ET.parse(tmp_path / "path.pvd").getroot().find("Collection")) == 3
