"""Charts that repair themselves (re-embedding, then splitting), or a refusal that says why."""
import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError
from pointatlas_atlas.atlas import AtlasSettings
from pointatlas_atlas.chart_repair import AtlasError, repair_neighbors
from pointatlas_atlas.partition import embedding_defects, refine_partition

from .test_atlas import make_atlas as _make_atlas
from .implicit_surfaces import sample_level_set, torus_tube

R, r = 1.0, 0.25     # a thin torus: 2 000 quasi-uniform points put 29 spacings round the tube



def make_atlas(**kw):
    return _make_atlas(**{"markers_per_patch": 150, **kw})


@pytest.fixture(scope="module")
def thin_torus():
    return sample_level_set(lambda x: torus_tube(x, R, r), [-R - r - 0.05] * 2 + [-r - 0.05],
                            [R + r + 0.05] * 2 + [r + 0.05], 2000)


@pytest.fixture(scope="module")
def repaired(thin_torus):
    return make_atlas().build(thin_torus)


def test_thin_torus_is_repaired_and_integrates_right(repaired):
    """Measured: PCA alone (no repair) left 206 of 209 patches failing, ∫K = 0.056·4π and
    area +3.3e-3; repaired, all 38 patches pass (NLIE), area −2.2e-4, ∫K = −5.1e-4·4π."""
    atlas = repaired
    assert atlas.accepted_.all()
    assert set(atlas.patch_embedder_) <= {"pca", "isomap", "nlie"}
    assert (atlas.patch_embedder_ != "pca").sum() > atlas.accepted_.size // 2
    assert atlas.patch_depth_.shape == atlas.accepted_.shape and atlas.patch_depth_.min() >= 0
    area = atlas.integrate(lambda q: np.ones(len(q.weights)))
    K = atlas.integrate(lambda q: q.geometry["gaussian_curvature"])
    assert area == pytest.approx(4 * np.pi**2 * R * r, rel=1e-3)
    assert abs(K) < 1e-2 * 4 * np.pi


def test_charts_use_the_embedding_that_passed(repaired):
    atlas = repaired
    pca = pointatlas.load_plugin("embedders", "pca")(n_components=2)
    n_pca_fails = 0
    for k, chart in enumerate(atlas.charts_):
        J = chart.node_index
        kept = atlas._embeddings[J.tobytes()]
        assert kept.passed and kept.embedder == atlas.patch_embedder_[k]
        np.testing.assert_array_equal(chart.xi_nodes, kept.xi)
        assert embedding_defects(atlas.points_[J], chart.xi_nodes)["flip_fraction"] == 0
        if kept.embedder != "pca":
            d = embedding_defects(atlas.points_[J], pca.fit_transform(atlas.points_[J]))
            n_pca_fails += not (d["flip_fraction"] == 0 and d["stress"] < 0.02
                                and d["distortion"] < 2.5)
    assert n_pca_fails > 0  # the repair was needed: PCA fails on these very control sets


def test_failing_patches_are_refused_with_where_and_what_to_try(thin_torus):
    # no curved patch embeds with distortion below 1.05: every patch fails every embedder
    kw = dict(max_distortion=1.05, max_refinement_depth=1, markers_per_patch=400)
    with pytest.raises(AtlasError) as err:
        make_atlas(**kw).partition(thin_torus)
    msg = str(err.value)
    assert "\n" not in msg
    assert msg.startswith("of", msg.index(" ") + 1)   # "<n> of <L> patches ..."
    assert "re-embedding (pca, nlie, isomap)" in msg and "up to 1 bisections" in msg
    assert 1 <= msg.count("markers across") <= 3 and "distortion" in msg
    for fix in ("more points", "atlas.markers_per_patch", "atlas.chart_reproduction=quartic",
                "atlas.allow_failed_patches=true"):
        assert fix in msg
    allowed = make_atlas(allow_failed_patches=True, **kw)
    allowed.partition(thin_torus)
    n_bad = int((~allowed.accepted_).sum())
    assert n_bad == allowed.accepted_.size and msg.startswith(f"{n_bad} of {n_bad} patches")
    assert allowed.refinement_warning().startswith(f"{n_bad} of {n_bad} patches")
    assert "they carry 100 % of the points" in allowed.refinement_warning()
    assert (allowed.patch_depth_ == 1).all()          # all were split once, then kept


def test_sphere_needs_no_repair():
    n = 1500                      # Fibonacci lattice: quasi-uniform, 150-marker caps are flat
    z = 1 - (2 * np.arange(n) + 1) / n
    t = np.pi * (3 - np.sqrt(5)) * np.arange(n)
    pts = np.column_stack([np.sqrt(1 - z**2) * np.cos(t), np.sqrt(1 - z**2) * np.sin(t), z])
    atlas = make_atlas(markers_per_patch=50)   # as many patches as the 5 000-point default
    atlas.partition(pts)
    assert atlas.accepted_.all() and (atlas.patch_depth_ == 0).all()
    assert set(atlas.patch_embedder_) == {"pca"} and atlas.refinement_warning() is None


def test_refine_partition_reports_split_depths():
    from pointatlas_atlas.partition import knn_graph

    x = np.random.default_rng(2).uniform(0, 1, (400, 3))
    A = knn_graph(x, 8)
    labels, ok, depth = refine_partition(np.zeros(400, np.int64), A, lambda idx: idx.size <= 60)
    sizes = np.bincount(labels)
    assert ok.all() and (sizes <= 60).all() and depth.shape == sizes.shape
    # every bisection about halves a patch: 400 → ≤ 60 markers takes 3 or more levels
    assert depth.min() >= 3 and np.all(sizes <= 400 / 2.0 ** depth * 1.5)


def test_repair_neighbors_and_settings():
    assert repair_neighbors(400, 2) == 12 and repair_neighbors(5, 2) == 4
    assert repair_neighbors(400, 1) == 8 and repair_neighbors(400, 3) == 16
    with pytest.raises(ConfigError,
                       match="^allow_failed_patches='yes' is invalid: it must be a bool"):
        AtlasSettings(allow_failed_patches="yes").check()
