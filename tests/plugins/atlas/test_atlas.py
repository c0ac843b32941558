"""The atlas of a point-set sphere: partition, partition of unity, area, Gauss–Bonnet."""
import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError
from pointatlas_atlas.atlas import Atlas, AtlasSettings
from pointatlas_atlas.partition import embedding_defects, is_connected, partition_markers


def make_atlas(**kw):
    s = AtlasSettings(**kw)
    return Atlas(
        s,
        make_embedder=lambda: pointatlas.load_plugin("embedders", "pca")(n_components=2),
        make_lme=lambda: pointatlas.load_plugin("approximants", "lme")(
            gamma=s.gamma_lme, tol=s.tol_lme, outside="flag"),
        make_pu=lambda: pointatlas.load_plugin("approximants", "shepard")(
            gamma=s.gamma_pu, tol=s.tol_pu, outside="flag"),
    )


@pytest.fixture(scope="module")
def sphere():
    return pointatlas.load_plugin("sources", "sphere")(n_points=1000).load(
        np.random.default_rng(0))


@pytest.fixture(scope="module")
def atlas(sphere):
    return make_atlas().build(sphere.points)


def test_partition_covers_markers_with_connected_patches(sphere):
    labels, A = partition_markers(sphere.points, 8)
    assert labels.shape == (1000,)
    L = labels.max() + 1
    assert L >= 8 and set(np.unique(labels)) == set(range(L))
    for k in range(L):
        assert is_connected(A, np.flatnonzero(labels == k))


def test_refined_patches_are_connected_and_acceptable(atlas):
    labels = atlas.labels_
    assert atlas.accepted_.all() and atlas.accepted_.shape == (len(atlas.charts_),)
    assert set(np.unique(labels)) == set(range(len(atlas.charts_)))
    for k in range(labels.max() + 1):
        assert is_connected(atlas.adjacency_, np.flatnonzero(labels == k))


def test_patch_partition_of_unity_sums_to_one(atlas):
    rng = np.random.default_rng(3)
    x = rng.standard_normal((500, 3))
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    x *= rng.uniform(0.98, 1.02, (500, 1))  # near the surface, off the markers
    psi = atlas.patch_pu(x).toarray()
    assert psi.shape == (500, len(atlas.charts_))
    assert (psi >= 0).all()
    assert np.allclose(psi.sum(1), 1.0, atol=1e-12)
    assert (psi.max(1) < 1).any()  # points in overlaps really are shared


def test_area_of_sphere(atlas):
    # measured: 4.9e-5 relative error at N = 1000 with the least-squares fit
    area = atlas.integrate(lambda q: np.ones(len(q.weights)))
    assert area == pytest.approx(4 * np.pi, rel=3e-4)


def test_gauss_bonnet_and_willmore(atlas):
    K = atlas.integrate(lambda q: q.geometry["gaussian_curvature"])
    W = atlas.integrate(lambda q: q.geometry["mean_curvature"] ** 2)
    assert K == pytest.approx(4 * np.pi, rel=3e-4)    # measured 4.5e-5
    assert W == pytest.approx(16 * np.pi, rel=2e-3)   # measured 3.1e-4


def test_per_chart_contributions_sum_and_redundancy(atlas):
    parts = atlas.integrate(lambda q: np.ones(len(q.weights)), per_chart=True)
    assert parts.shape == (len(atlas.charts_),) and (parts > 0).all()
    assert parts.sum() == pytest.approx(atlas.integrate(lambda q: np.ones(len(q.weights))))
    assert 1.0 < atlas.redundancy() < 5.0
    assert max(c.fit_residual for c in atlas.charts_) < 1e-10


def test_without_least_squares_fit_area_shrinks(sphere):
    # LME is not interpolating: the chart lies inside the sphere, area error ~1e-2 at N = 1000
    a = make_atlas(least_squares_fit=False).build(sphere.points)
    area = a.integrate(lambda q: np.ones(len(q.weights)))
    assert 1e-3 < (4 * np.pi - area) / (4 * np.pi) < 5e-2


def test_fold_detected_by_embedding_defects():
    rng = np.random.default_rng(0)
    uv = rng.uniform(-1, 1, (300, 2))
    flat = np.column_stack([uv, 0.1 * uv[:, 0] ** 2])
    ok = embedding_defects(flat, uv)
    assert ok["flip_fraction"] == 0 and ok["stress"] < 0.01
    # a half cylinder projected on its chord plane folds nothing but is distorted ...
    t = rng.uniform(0.05, np.pi - 0.05, 400)
    z = rng.uniform(0, 1, 400)
    tube = np.column_stack([np.cos(t), np.sin(t), z])
    proj = embedding_defects(tube, np.column_stack([np.cos(t), z]))
    assert proj["distortion"] > 3 or proj["stress"] > 0.05
    # ... and a fold (ξ = |u|) flips triangles
    fold = embedding_defects(flat, np.column_stack([np.abs(uv[:, 0]), uv[:, 1]]))
    assert fold["flip_fraction"] > 0


@pytest.mark.parametrize("turn_degrees", [60.0, 100.0])
def test_a_chart_across_a_crease_is_not_a_fold(turn_degrees):
    """Two half-planes meeting at a crease where the normal turns by φ, projected on their
    bisector plane (a graph: no fold). Triangles straddling the crease have normals up to φ
    apart, n_t·n_s < 0 past 90°; only a reversal (n_t·n_s < FOLD_COSINE = cos 120°) is a
    fold. The same points with ξ folded across the crease (ξ = (u, |v|)) fold."""
    from pointatlas_atlas.partition import FOLD_COSINE

    assert FOLD_COSINE == pytest.approx(np.cos(np.radians(120.0)))
    rng = np.random.default_rng(3)
    uv = rng.uniform(-1, 1, (600, 2))
    slope = np.tan(np.radians(turn_degrees / 2))
    P = np.column_stack([uv, slope * np.abs(uv[:, 0])])     # normals ±φ/2 off the z axis
    chart = embedding_defects(P, uv)
    assert chart["flip_fraction"] == 0.0
    folded = embedding_defects(P, np.column_stack([uv[:, 0], np.abs(uv[:, 1])]))
    assert folded["flip_fraction"] > 0.0


def test_bad_settings_raise():
    with pytest.raises(ConfigError, match="gamma_pu"):
        make_atlas(gamma_pu=-1.0).build(np.random.default_rng(0).standard_normal((50, 3)))


def test_thin_pipe_is_repaired_or_refused_never_silently_folded(atlas):
    """Today's code accepted the pipe's folded PCA charts with a warning only. Now a patch
    failing the chart test is re-embedded (Isomap, NLIE), then split; what still fails at the
    depth limit is refused (AtlasError), unless allow_failed_patches keeps it, flagged."""
    from pointatlas_atlas.chart_repair import AtlasError

    assert atlas.refinement_warning() is None  # the sphere's charts all pass
    rng = np.random.default_rng(1)
    t, z = rng.uniform(0, 2 * np.pi, 600), rng.uniform(-2.0, 2.0, 600)
    thin_pipe = np.column_stack([0.3 * np.cos(t), 0.3 * np.sin(t), z])  # 8 spacings round
    with pytest.raises(AtlasError, match=r"^\d+ of \d+ patches of the atlas fail"):
        make_atlas(markers_per_patch=60, max_refinement_depth=1).partition(thin_pipe)
    pipe = make_atlas(markers_per_patch=60, max_refinement_depth=1, allow_failed_patches=True)
    pipe.partition(thin_pipe)
    n_bad = int((~pipe.accepted_).sum())
    assert 0 < n_bad < pipe.accepted_.size
    assert "nlie" in set(pipe.patch_embedder_)           # the repair re-embedded some
    message = pipe.refinement_warning()
    assert message.startswith(f"{n_bad} of {pipe.accepted_.size} patches")
    for fix in ("more points", "markers_per_patch", "chart_reproduction=quartic"):
        assert fix in message
