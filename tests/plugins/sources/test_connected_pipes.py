import numpy as np
import pytest

from pointatlas.errors import ConfigError
from pointatlas_sources.connected_pipes import (
    ConnectedPipes,
    pipes_area,
    pipes_bounds,
    pipes_function,
    pipes_gradient,
    project_to_surface,
)

from .conftest import nn_distances


DEFAULT = (1.2, 0.45, 0.9)  # core_level m, half_width w, height ζ


def contour_mesh(params=DEFAULT, h=0.03):
    """Triangle mesh of F = 0 from pyvista's contour of F sampled on a grid."""
    pv = pytest.importorskip("pyvista")
    lo, hi = pipes_bounds(*params)
    lo, hi = lo - 0.05, hi + 0.05
    dims = np.ceil((hi - lo) / h).astype(int) + 1
    grid = pv.ImageData(dimensions=dims, spacing=(h, h, h), origin=lo)
    grid["F"] = pipes_function(np.asarray(grid.points), *params)
    return grid.contour([0.0], scalars="F").triangulate().clean()


def euler_characteristic(mesh):
    faces = mesh.faces.reshape(-1, 4)[:, 1:]
    edges = np.vstack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    n_edges = len(np.unique(np.sort(edges, axis=1), axis=0))
    return mesh.n_points - n_edges + len(faces)


def test_gradient_matches_finite_differences():
    X = np.random.default_rng(0).uniform(-1, 1, (20, 3))
    eps = 1e-6
    fd = np.column_stack([
        (pipes_function(X + eps * e, *DEFAULT) - pipes_function(X - eps * e, *DEFAULT))
        / (2 * eps) for e in np.eye(3)])
    np.testing.assert_allclose(pipes_gradient(X, *DEFAULT), fd, rtol=1e-6, atol=1e-8)


@pytest.mark.parametrize("params", [DEFAULT, (1.0, 0.4, 0.8), (0.9, 0.3, 1.2)])
def test_surface_has_genus_two(params):
    assert euler_characteristic(contour_mesh(params)) == -2


def test_area_reference_is_converged_and_matches_a_mesh():
    """The graph-integral area converges spectrally (1.2e-10 at 200×200 nodes vs 400×400);
    a marching-cubes mesh with vertices projected onto F = 0 has O(h²) error: Richardson
    extrapolation of h = 0.04 and 0.02 must land close to it."""
    ref = pipes_area(*DEFAULT, n_nodes=300, n_angles=300)
    assert pipes_area(*DEFAULT) == pytest.approx(ref, rel=1e-9)
    assert ref == pytest.approx(21.87185879485, rel=1e-10)
    areas = []
    for h in (0.04, 0.02):
        mesh = contour_mesh(DEFAULT, h)
        mesh.points = project_to_surface(np.asarray(mesh.points), *DEFAULT)
        areas.append(mesh.area)
    assert abs(areas[1] - ref) < abs(areas[0] - ref) / 3  # O(h²)
    assert (4 * areas[1] - areas[0]) / 3 == pytest.approx(ref, rel=2e-5)


@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_points_on_the_surface(sampling):
    src = ConnectedPipes(n_points=1500, sampling=sampling, scale=3.0)
    pc = src.load(np.random.default_rng(0))
    assert pc.points.shape == (1500, 3)
    assert np.abs(src.implicit_function(pc.points)).max() < 1e-8
    assert pc.exact["euler_characteristic"] == -2 and pc.exact["genus"] == 2
    assert pc.exact["area"] == pytest.approx(9.0 * 21.87185879485, rel=1e-9)
    assert pc.intrinsic_dim == 2
    lo, hi = pipes_bounds(*DEFAULT)
    assert np.all(pc.points >= 3.0 * lo - 1e-9) and np.all(pc.points <= 3.0 * hi + 1e-9)


def test_structured_is_quasi_uniform_and_deterministic():
    src = ConnectedPipes(n_points=1500)
    X = src.load(np.random.default_rng(0)).points
    d = nn_distances(X)
    assert d.min() / d.mean() > 0.5
    np.testing.assert_array_equal(X, src.load(np.random.default_rng(1)).points)


def test_random_density_is_uniform_in_area():
    """Share of points in the central crossing region (|x| < 0.3) equals its area share
    on the contour mesh (which is accurate to a few per mille at this grid size)."""
    mesh = contour_mesh(DEFAULT, h=0.02)
    cell_centres = np.asarray(mesh.cell_centers().points)
    areas = np.asarray(mesh.compute_cell_sizes(length=False, volume=False)["Area"])
    share = areas[np.abs(cell_centres[:, 0]) < 0.3].sum() / areas.sum()
    n = 20000
    X = ConnectedPipes(n_points=n, sampling="random").load(np.random.default_rng(2)).points
    observed = (np.abs(X[:, 0]) < 0.3).mean()
    sigma = np.sqrt(share * (1 - share) / n)
    assert abs(observed - share) < 4 * sigma + 0.005


def test_random_seeding():
    src = ConnectedPipes(n_points=300, sampling="random", n_markers=100)
    a = src.load(np.random.default_rng(3))
    b = src.load(np.random.default_rng(3))
    np.testing.assert_array_equal(a.points, b.points)
    np.testing.assert_array_equal(a.markers, b.markers)
    assert not np.allclose(a.points, src.load(np.random.default_rng(4)).points)
    assert np.abs(src.implicit_function(a.markers)).max() < 1e-8


@pytest.mark.parametrize("kw", [dict(core_level=0.4), dict(core_level=1.6),
                                dict(core_level=1.0, half_width=1.2), dict(half_width=0.0),
                                dict(height=-1.0)])
def test_bad_shape(kw):
    with pytest.raises(ConfigError, match="core_level|half_width|height"):
        ConnectedPipes(**kw).load(np.random.default_rng(0))
