"""Ghost nodes beyond the boundary (Paper 1 §4.1.2): on the continued surface, distinct."""
import numpy as np
import pytest
from scipy.spatial import cKDTree

import pointatlas
from pointatlas.errors import ConfigError
from pointatlas_atlas.boundary import boundary_mask
from pointatlas_atlas.ghosts import ghost_points


def load(name, n, sampling="structured", seed=0, **kw):
    cls = pointatlas.load_plugin("sources", name)
    return cls(n_points=n, sampling=sampling, **kw).load(np.random.default_rng(seed))


def min_separation(X, G):
    return min(cKDTree(X).query(G)[0].min(), cKDTree(G).query(G, k=2)[0][:, 1].min())


@pytest.mark.parametrize("layers", [1, 2, 3])
def test_structured_plate_ghosts_extend_the_grid_including_corners(layers):
    pc = load("square_plate", 441)
    X, h = pc.points, 10.0 / (np.sqrt(len(pc.points)) - 1)
    G = ghost_points(X, boundary_mask(X), layers=layers)
    ticks = np.arange(-5 - layers * h, 5 + layers * h + h / 2, h)
    grid = np.array([[a, b, 0.0] for a in ticks for b in ticks])
    both = np.vstack([X, G])
    assert len(both) == len(grid)  # exactly the extended grid, corners filled
    d, _ = cKDTree(grid).query(both)
    assert d.max() < 1e-9
    assert len(np.unique(np.round(both / h).astype(int), axis=0)) == len(both)


@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_random_plate_ghosts_are_outside_and_distinct(sampling):
    pc = load("square_plate", 400, sampling, seed=3)
    X = pc.points
    G = ghost_points(X, boundary_mask(X))
    assert np.all(np.abs(G[:, :2]).max(axis=1) > 5.0 + 0.3 * pc.exact["spacing"])
    assert np.all(np.abs(G[:, :2]).max(axis=1) < 5.0 + 2.6 * pc.exact["spacing"])
    np.testing.assert_allclose(G[:, 2], 0.0, atol=1e-12)
    assert min_separation(X, G) > 0.35 * pc.exact["spacing"]
    for corner in ([6, 6], [-6, 6], [6, -6], [-6, -6]):  # the corner regions are filled
        assert np.min(np.linalg.norm(G[:, :2] - corner, axis=1)) < 1.5


@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_sphere_extension_is_third_order(sampling):
    """Ghosts of the open hemisphere stay within C h³/R² of the sphere of radius 10."""
    errors, spacings = [], []
    for n in (400, 1600):
        pc = load("hemisphere", n, sampling, hole_angle_deg=18.0)
        X = pc.points
        G = ghost_points(X, boundary_mask(X))
        assert len(G) > 1.8 * boundary_mask(X).sum()
        assert min_separation(X, G) > 0.35 * pc.exact["spacing"]
        errors.append(np.abs(np.linalg.norm(G, axis=1) - 10.0).max())
        spacings.append(pc.exact["spacing"])
        assert errors[-1] < 1.0 * spacings[-1] ** 3 / 10.0**2 * 10
    assert errors[0] / errors[1] > 6.0  # h halves: error falls at least ~h³


def test_cylinder_ghosts_beyond_all_edges_stay_on_the_cylinder():
    pc = load("cylinder", 1600, model="quarter")
    X, h = pc.points, pc.exact["spacing"]
    G = ghost_points(X, boundary_mask(X))
    rho = np.hypot(G[:, 0], G[:, 1])
    assert np.abs(rho - 300.0).max() < 10 * h**3 / 300.0**2
    assert (G[:, 2] > 300).any() and (G[:, 2] < -300).any()
    assert (G[:, 0] < 0).any() and (G[:, 1] < 0).any()  # beyond the symmetry edges
    assert min_separation(X, G) > 0.45 * h


def test_options_and_errors():
    X = load("square_plate", 121).points
    mask = boundary_mask(X)
    assert ghost_points(X, np.zeros(len(X), bool)).shape == (0, 3)
    G = ghost_points(X, mask, layers=1, spacing=2.0)
    assert np.abs(G[:, :2]).max() == pytest.approx(7.0)
    with pytest.raises(ConfigError, match="layers"):
        ghost_points(X, mask, layers=0)
    with pytest.raises(ConfigError, match="spacing"):
        ghost_points(X, mask, spacing=-1.0)
