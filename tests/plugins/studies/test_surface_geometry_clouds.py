"""surface_geometry on clouds that are not one smooth manifold (issue 16, item 4)."""
import os

import numpy as np
import pytest

from pointatlas.context import RunContext
from pointatlas.errors import InputError
from pointatlas_studies.surface_geometry import SurfaceGeometry

from ..atlas.test_cloud_checks import cube_surface


def fibonacci_sphere(n, radius=1.0, centre=(0.0, 0.0, 0.0)):
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    phi = np.pi * (1 + 5 ** 0.5) * i
    r = np.sqrt(1 - z * z)
    return radius * np.c_[r * np.cos(phi), r * np.sin(phi), z] + np.asarray(centre)




def pyvista_file(name):
    pytest.importorskip("pyvista")
    from pyvista import examples

    return os.path.join(os.path.dirname(examples.__file__), name)


def run_file(tmp_path, path):
    """The default command on a file: sphere_willmore's study settings, pca embedder."""
    ctx = RunContext(config={"source": {"path": str(path), "n_points": None}, "study": {}},
                     choices={"source": "file", "study": "surface_geometry", "embedder": "pca"},
                     seed=0, run_dir=tmp_path)
    return SurfaceGeometry().run(ctx)


def saved(tmp_path, points):
    path = tmp_path / "points.npz"
    np.savez(path, points=points)
    return path


def test_two_spheres_are_reported_per_component(tmp_path):
    """Two disjoint Fibonacci spheres (radii 1 and 0.7) and 3 stray points: one atlas per
    sphere, areas 4π and 4π·0.49 per component, totals the sums, the strays counted."""
    rng = np.random.default_rng(0)
    stray = rng.uniform(-0.1, 0.1, (3, 3)) + [1.5, 3.0, 0.0]
    P = np.concatenate([fibonacci_sphere(1500), fibonacci_sphere(1000, 0.7, (3.0, 0, 0)), stray])
    ds = run_file(tmp_path, saved(tmp_path, P))
    assert ds.sizes["component"] == 2
    assert ds["component_n_points"].values.tolist() == [1500, 1000]
    exact = 4 * np.pi * np.array([1.0, 0.49])
    assert np.allclose(ds["component_area"].values, exact, rtol=2e-3)
    assert np.allclose(ds["component_total_gaussian_curvature"].values, 4 * np.pi, rtol=2e-2)
    assert float(ds["area"]) == pytest.approx(float(ds["component_area"].sum()))
    assert float(ds["willmore_energy"]) == pytest.approx(
        float(ds["component_willmore_energy"].sum()))
    assert int(ds["n_points"]) == 2500 and int(ds["n_isolated_points"]) == 3
    assert ds.sizes["patch"] == int(ds["n_patches"])
    assert sorted(set(ds["patch_component"].values.tolist())) == [0, 1]
    assert float(ds["patch_area"].sum()) == pytest.approx(float(ds["area"]))
    for v in list(ds.data_vars) + list(ds.coords):
        assert "long_name" in ds[v].attrs and "units" in ds[v].attrs, v


def test_cube_surface_is_refused_for_its_creases(tmp_path):
    with pytest.raises(InputError, match=r"^points: this cloud has creases; the curvature "
                                         r"integrals of a smooth atlas do not apply there: "
                                         r"384 points on creases \(of 1536\), e\.g\. near \("):
        run_file(tmp_path, saved(tmp_path, cube_surface(16)))


def test_cube_surface_with_allow_creases_is_computed_and_flagged(tmp_path):
    """atlas.allow_creases: the integrals of the smooth atlas through a cube's points are
    computed, and the results say why they are not trustworthy (the crease warning, hence
    status completed_with_warnings). ∫K is still 4π (Gauss–Bonnet does not care how the edges
    are rounded: measured 0.9989 · 4π); the area is 3 % short of 24 (rounded edges)."""
    path = saved(tmp_path, cube_surface(16))
    ctx = RunContext(config={"source": {"path": str(path), "n_points": None}, "study": {},
                             "atlas": {"allow_creases": True}},
                     choices={"source": "file", "study": "surface_geometry", "embedder": "pca",
                              "atlas": "default"}, seed=0, run_dir=tmp_path)
    ds = SurfaceGeometry().run(ctx)
    assert ds.attrs["warnings"].startswith(
        "points: kept by atlas.allow_creases=true, but this cloud has creases; the curvature "
        "integrals of a smooth atlas do not apply there: 384 points on creases (of 1536)")
    assert int(ds["n_unaccepted_patches"]) == 0
    assert float(ds["total_gaussian_curvature"]) == pytest.approx(4 * np.pi, rel=5e-3)
    assert 0.95 * 24 < float(ds["area"]) < 24


@pytest.mark.parametrize("name, match", [
    ("nut.ply", r"nut: this cloud has creases; .*: 370 points on creases \(of 523\)"),
    ("ant.ply", r"ant: this cloud has creases; .* with neighbourhoods that are not a disc"),
    ("airplane.ply", r"airplane: this cloud is too unevenly sampled for one chart scale: "
                     r"718 of its 1335 points are isolated"),
])
def test_pyvista_meshes_that_are_not_one_smooth_surface_are_refused(tmp_path, name, match):
    with pytest.raises(InputError, match=match) as info:
        run_file(tmp_path, pyvista_file(name))
    assert "\n" not in str(info.value)


def test_pyvista_sphere_passes_the_checks_unchanged():
    """sphere.ply (422 uneven points): not refused, one component, nothing dropped, the
    cloud handed on as read."""
    from pointatlas_sources.point_file import PointFile
    from pointatlas_studies.component_results import checked_components

    cloud = PointFile(path=pyvista_file("sphere.ply")).load()
    parts, comp, kept = checked_components(cloud, 10)
    assert parts == [cloud] and kept is None and comp.n_isolated == 0 and comp.sizes.tolist() == [422]


@pytest.mark.slow
def test_pyvista_sphere_is_refused_or_right(tmp_path):
    """sphere.ply (422 uneven points), issue 16's bar: the default command refuses it in one
    line naming the fix (its spacing varies by 41 %); the fix it names (quartic charts) gives
    ∫K within 2 % of 4π and the Willmore energy within 5 % of 16π, every chart accepted
    (measured: −1.03 % and −0.71 %)."""
    with pytest.raises(InputError, match="chart_reproduction=quartic") as info:
        run_file(tmp_path / "default", pyvista_file("sphere.ply"))
    assert "\n" not in str(info.value)
    ctx = RunContext(config={"source": {"path": pyvista_file("sphere.ply"), "n_points": None},
                             "study": {}, "atlas": {"chart_reproduction": "quartic"}},
                     choices={"source": "file", "study": "surface_geometry", "embedder": "pca",
                              "atlas": "default"}, seed=0, run_dir=tmp_path / "quartic")
    ds = SurfaceGeometry().run(ctx)
    assert int(ds["n_points"]) == 422 and int(ds["n_isolated_points"]) == 0
    assert "component" not in ds.dims and int(ds["n_unaccepted_patches"]) == 0
    assert float(ds["total_gaussian_curvature"]) == pytest.approx(4 * np.pi, rel=0.02)
    assert float(ds["willmore_energy"]) == pytest.approx(16 * np.pi, rel=0.05)


def test_generated_sphere_keeps_its_figures(tmp_path):
    ctx = RunContext(config={"source": {"n_points": 800}, "study": {}},
                     choices={"source": "sphere", "study": "surface_geometry", "embedder": "pca"},
                     seed=0, run_dir=tmp_path)
    ds = SurfaceGeometry().run(ctx)
    assert int(ds["n_isolated_points"]) == 0 and "cloud_checks" in ctx.timings
    assert float(ds["relative_error_willmore_energy"]) < 3e-3


@pytest.mark.slow
def test_a_parametric_ellipsoid_grid_with_quartic_charts(tmp_path):
    """pyvista's ParametricEllipsoid(1.5, 1, 0.7) at 80 × 80 (6 164 distinct points on
    meridians up to three spacings apart, crowded at the poles) with the polynomial-fit
    charts the irregular-spacing refusal names (README, Known limits: quartic charts,
    chart_margin 5, gamma_pu 2). Quartic charts used to end 'completed' with ∫K dA = 0.657
    and a Willmore energy of 313 536; measured now: ∫K −0.26 %, Willmore −0.18 %, area
    −0.06 % against the exact 4π, 62.95380 and 13.98425 (the last two by a 1 000 × 2 000
    midpoint rule in the test's own parametrisation), 27 s. (With the 3h margin that
    polynomial charts had before, the area fell 0.57 % short: about one meridian gap.)"""
    pv = pytest.importorskip("pyvista")
    m = pv.ParametricEllipsoid(1.5, 1.0, 0.7, u_res=80, v_res=80, w_res=80)
    P = np.unique(np.asarray(m.points, dtype=np.float64).round(6), axis=0)
    path = tmp_path / "ellipsoid.npz"
    np.savez(path, points=P)
    a, b, c = 1.5, 1.0, 0.7
    n = 1000
    t, f = np.meshgrid((np.arange(n) + 0.5) / n * np.pi,
                       (np.arange(2 * n) + 0.5) / (2 * n) * 2 * np.pi, indexing="ij")
    X = np.stack([a * np.sin(t) * np.cos(f), b * np.sin(t) * np.sin(f), c * np.cos(t)], -1)
    Xt = np.stack([a * np.cos(t) * np.cos(f), b * np.cos(t) * np.sin(f), -c * np.sin(t)], -1)
    Xf = np.stack([-a * np.sin(t) * np.sin(f), b * np.sin(t) * np.cos(f), 0 * t], -1)
    dA = np.linalg.norm(np.cross(Xt, Xf), axis=-1) * (np.pi / n) ** 2
    x, y, z = X[..., 0], X[..., 1], X[..., 2]
    S = x**2 / a**4 + y**2 / b**4 + z**2 / c**4
    H = (x * x + y * y + z * z - a * a - b * b - c * c) / (a * a * b * b * c * c * S**1.5)
    ctx = RunContext(config={"source": {"path": str(path), "n_points": None}, "study": {},
                             "atlas": {"chart_reproduction": "quartic", "chart_margin": 5.0,
                                       "gamma_pu": 2.0, "least_squares_fit": False}},
                     choices={"source": "file", "study": "surface_geometry", "embedder": "pca",
                              "atlas": "default"}, seed=0, run_dir=tmp_path)
    ds = SurfaceGeometry().run(ctx)
    assert int(ds["n_points"]) == 6164
    assert int(ds["n_unaccepted_patches"]) == 0 and "warnings" not in ds.attrs
    assert float(ds["total_gaussian_curvature"]) == pytest.approx(4 * np.pi, rel=0.01)
    assert float(ds["willmore_energy"]) == pytest.approx(float(np.sum(H * H * dA)), rel=5e-3)
    assert float(ds["area"]) == pytest.approx(float(np.sum(dA)), rel=2e-3)
