"""Six connected open pipes (three crossing pipes, six open ends; thesis Fig. 17 stand-in)."""
import dataclasses
import inspect

import numpy as np
import pytest

from pointatlas.errors import ConfigError
from pointatlas_sources.six_pipes import (SixPipes, junction_box_area, junction_box_half_size,
                                          six_pipes_value_gradient)

R, H, K = 0.475, 1.5, 0.3  # defaults: D/2, L/2, blend


@pytest.fixture(scope="module")
def clouds():
    return {s: SixPipes(n_points=2000, sampling=s).load(np.random.default_rng(0))
            for s in ("structured", "random")}


def test_config_matches_keyword_only_init():
    fields = {f.name: f.default for f in dataclasses.fields(SixPipes.Config)}
    params = {k: p for k, p in inspect.signature(SixPipes.__init__).parameters.items()
              if k != "self"}
    assert {k: p.default for k, p in params.items()} == fields
    assert all(p.kind is p.KEYWORD_ONLY for p in params.values())
    assert (fields["pipe_length"], fields["pipe_diameter"]) == (3.0, 0.95)  # thesis Fig. 17


@pytest.mark.parametrize("sampling", ["structured", "random"])
def test_points_lie_on_the_surface_with_six_end_circles(clouds, sampling):
    pc = clouds[sampling]
    X = pc.points
    assert len(X) == 2000 and len(np.unique(X, axis=0)) == 2000
    assert np.abs(six_pipes_value_gradient(X, R, K)[0]).max() < 1e-12
    assert np.abs(X).max() <= H + 1e-12
    for axis in range(3):
        for end in (-H, H):
            ring = X[np.abs(X[:, axis] - end) < 1e-12]
            assert len(ring) >= 8
            others = np.delete(ring, axis, axis=1)
            np.testing.assert_allclose(np.linalg.norm(others, axis=1), R, atol=1e-12)
    from scipy.spatial import cKDTree
    d = cKDTree(X).query(X, k=2)[0][:, 1]
    assert d.min() > 0.5 * np.median(d)               # quasi-uniform, no clusters
    assert pc.exact["euler_characteristic"] == -4 and pc.exact["n_boundary_curves"] == 6


@pytest.mark.parametrize("n", [1500, 2000, 2317])
def test_structured_cloud_is_mirror_symmetric_point_for_point(n):
    from scipy.spatial import cKDTree

    pc = SixPipes(n_points=n).load(np.random.default_rng(0))
    X = pc.points
    assert len(X) == n
    distance, _ = cKDTree(X).query(X * np.array([-1.0, 1.0, 1.0]))
    assert distance.max() < 1e-12
    d = cKDTree(X).query(X, k=2)[0][:, 1]
    assert d.min() > 0.5 * np.median(d)


def test_area_against_a_monte_carlo_shell_volume():
    """The mesh-based junction area against an estimator that uses no mesh: the volume of the
    shell |F| < δ|∇F| in the junction box by uniform sampling, divided by 2δ (bias O(δ²κ²),
    statistical error ≈ 0.1 % here)."""
    c = junction_box_half_size(R, K)
    rng, delta, hits, n = np.random.default_rng(1), 0.01, 0, 0
    for _ in range(8):
        X = rng.uniform(-c, c, (500_000, 3))
        F, G = six_pipes_value_gradient(X, R, K)
        hits += int(np.sum(np.abs(F) < delta * np.linalg.norm(G, axis=1)))
        n += len(X)
    estimate = hits / n * (2 * c) ** 3 / (2 * delta)
    assert junction_box_area(R, K) == pytest.approx(estimate, rel=0.006)


def test_the_surface_is_a_sphere_with_six_holes():
    """χ = V − E + F of a marching-cubes mesh of the whole surface (pyvista), cut at the
    pipe ends: −4, and six boundary loops."""
    import pyvista as pv

    g = R / 10
    n = int(np.ceil(2 * H / g)) + 1
    grid = pv.ImageData(dimensions=(n, n, n), spacing=(2 * H / (n - 1),) * 3,
                        origin=(-H, -H, -H))
    grid["F"] = six_pipes_value_gradient(np.asarray(grid.points), R, K)[0]
    mesh = grid.contour([0.0], scalars="F").triangulate().clean()
    edges = mesh.extract_all_edges()
    chi = mesh.n_points - edges.n_cells + mesh.n_cells
    assert chi == -4
    loops = mesh.extract_feature_edges(boundary_edges=True, feature_edges=False,
                                       manifold_edges=False, non_manifold_edges=False)
    assert loops.connectivity().point_data["RegionId"].max() + 1 == 6


@pytest.mark.parametrize("kwargs, word", [({"blend": 0.6}, "blend"),
                                          ({"pipe_length": 1.0}, "pipe_length"),
                                          ({"n_points": 50}, "n_points"),
                                          ({"pipe_diameter": -1.0}, "pipe_diameter")])
def test_bad_parameters(kwargs, word):
    with pytest.raises(ConfigError, match=word):
        SixPipes(**kwargs).load(np.random.default_rng(0))
