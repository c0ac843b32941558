"""A departing chart is split into charts on its halves (departure_repair): the result is the
atlas partitioned that way from the start, and a split is kept only while it helps."""
import numpy as np
import pytest

import pointatlas_approximants.weighted_polynomial_fit as wpf
import pointatlas_atlas.atlas as atlas_module
import pointatlas_atlas.departure_repair as repair
from .test_chart_fidelity import grid_ellipsoid, quartic_atlas


@pytest.fixture(scope="module")
def unguarded_atlas():
    """pyvista's ParametricEllipsoid grid with the Lebesgue guard of the quartic fit off:
    charts depart from their points (test_chart_fidelity), some less once split; flagged."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(wpf, "MAX_LEBESGUE", np.inf)
        yield quartic_atlas(allow_failed_patches=True).build(grid_ellipsoid())


def by_first_marker(atlas):
    """Chart index per patch, keyed by the patch's first marker (labels are relabelled)."""
    return {int(np.flatnonzero(atlas.labels_ == k)[0]): k for k in range(len(atlas.charts_))}


def test_a_split_atlas_equals_the_atlas_partitioned_that_way(unguarded_atlas, monkeypatch):
    split = unguarded_atlas
    L0 = split.initial_n_patches_
    assert split.departed_splits_ >= 1 and len(split.charts_) > L0
    assert len(split.quadrature_) == len(split.support_) == split.accepted_.size == \
        split.patch_depth_.size == split.patch_embedder_.size == int(split.labels_.max()) + 1
    assert split.accepted_.all() and (split.patch_depth_[L0:] >= 1).all()
    assert "none" not in set(split.patch_embedder_)

    # the reference: METIS returns the repaired labels, no chart is split afterwards
    labels = split.labels_.copy()
    real_partition = atlas_module.partition_markers
    monkeypatch.setattr(atlas_module, "partition_markers",
                        lambda Q, n, k: (labels, real_partition(Q, n, k)[1]))
    monkeypatch.setattr(repair, "split_departed_charts", lambda *a, **kw: 0)
    monkeypatch.setattr(wpf, "MAX_LEBESGUE", np.inf)
    ref = quartic_atlas(allow_failed_patches=True).build(grid_ellipsoid())
    assert len(ref.charts_) == len(split.charts_)

    mine, theirs = by_first_marker(split), by_first_marker(ref)
    for first, k in mine.items():
        j = theirs[first]
        q, r = split.quadrature_[k], ref.quadrature_[j]
        np.testing.assert_allclose(q.weights, r.weights, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(q.positions, r.positions, rtol=1e-12, atol=1e-12)
        assert q.departure == r.departure
        assert split.chart_orientation_[k] * split.chart_orientation_[0] == \
            ref.chart_orientation_[j] * ref.chart_orientation_[theirs[min(mine)]]
    K = [a.integrate(lambda qp: qp.geometry["gaussian_curvature"]) for a in (split, ref)]
    assert K[0] == pytest.approx(K[1], rel=1e-12)


def test_splitting_stops_where_it_does_not_help(unguarded_atlas):
    """The unguarded fit departs at any chart size: halves that depart on more than half the
    area their chart did are not split again (not down to max_refinement_depth)."""
    atlas = unguarded_atlas
    assert not atlas.charts_faithful().all()      # still flagged: splitting did not cure it
    assert atlas.patch_depth_.max() < atlas.settings.max_refinement_depth
    assert "depart from their points" in atlas.refinement_warning()


def test_a_globally_fitted_atlas_is_not_split():
    class Fitted:
        settings = type("S", (), {"least_squares_scope": "global", "max_refinement_depth": 6})

        def interpolates(self):
            return True

    atlas = Fitted()
    assert repair.split_departed_charts(atlas, [], None, True, False, None) == 0
    assert atlas.departed_splits_ == 0
