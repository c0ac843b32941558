"""A chart's share of the partition of unity must stay off the rim of its domain, where an LME
chart flattens to chords and past which nothing is integrated. pyvista's ParametricEllipsoid
grid (made by VTK, not here; meridians up to three spacings apart, which the median spacing
does not see) put ψ = 1 on chart rims with the default 3h margin of linear charts, and the
atlas was built without a word, its area 0.11 % (60 × 60) and 0.59 % (80 × 80) short; it is
now refused in one line naming atlas.chart_margin, or flagged."""
import numpy as np
import pytest

from pointatlas_atlas.chart_coverage import MAX_EDGE_PU, pu_at_chart_edges
from pointatlas_atlas.chart_repair import AtlasError

from .test_atlas import make_atlas as atlas


def test_rim_weight_counts_only_points_inside_another_chart():
    """Two 1-D charts on points 0…9: A on 0…5, B on 4…9. Points 0 and 9 are the cloud's own
    ends (rim vertices of every chart that holds them), 5 lies inside B and 4 inside A."""
    nodes = [np.arange(0, 6), np.arange(4, 10)]
    xis = [J[:, None].astype(float) for J in nodes]
    psi_a = np.array([1.0, 1.0, 1.0, 1.0, 0.5, 0.0])      # A's rim at 5 carries nothing
    psi_b = np.array([0.5, 1.0, 1.0, 1.0, 1.0, 1.0])      # B's rim at 4 carries 0.5
    edge, where = pu_at_chart_edges(nodes, xis, [psi_a, psi_b], 10)
    assert edge.tolist() == [0.0, 0.5] and where[1] == 4
    real = np.ones(10, bool)
    real[4] = False                                         # a ghost node is not integrated
    edge, _ = pu_at_chart_edges(nodes, xis, [psi_a, psi_b], 10, real=real)
    assert edge.tolist() == [0.0, 0.0]


def grid_ellipsoid(res=60):
    pv = pytest.importorskip("pyvista")
    m = pv.ParametricEllipsoid(1.5, 1.0, 0.7, u_res=res, v_res=res, w_res=res)
    return np.unique(np.asarray(m.points, dtype=np.float64).round(9), axis=0)


def test_a_parametric_grid_is_refused_or_flagged_and_right_with_the_margin_named():
    P = grid_ellipsoid()                                        # 3 424 points
    with pytest.raises(AtlasError, match=r"charts carry partition-of-unity weight on the rim"
                                         r".*chart \d+ near \(.*atlas.chart_margin \(try 4.8\)"
                       ) as info:
        atlas().build(P)
    assert "\n" not in str(info.value)
    flagged = atlas(allow_failed_patches=True).build(P)
    assert (flagged.edge_pu_ > MAX_EDGE_PU).any() and flagged.charts_faithful().all()
    assert "rim of their domain" in flagged.refinement_warning()
    assert float(flagged.quadrature_points().weights.sum()) < 13.98426 * (1 - 1e-3)  # lost
    wider = atlas(chart_margin=4.8).build(P)                    # the margin the refusal names
    assert wider.edge_pu_.max() <= MAX_EDGE_PU and wider.refinement_warning() is None
    assert float(wider.quadrature_points().weights.sum()) == pytest.approx(13.98426, rel=2e-3)


def test_a_quasi_uniform_sphere_and_an_open_disc_keep_their_rims_clear():
    n = 2000
    i = np.arange(n) + 0.5
    phi, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    sphere = np.c_[np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)]
    a = atlas().build(sphere)
    assert a.edge_pu_.max() <= MAX_EDGE_PU and a.refinement_warning() is None
    r, t = np.sqrt(i / n), np.pi * (1 + 5 ** 0.5) * i          # a Fibonacci disc: open, its
    disc = np.c_[r * np.cos(t), r * np.sin(t), 0.1 * r ** 2]   # edge is the cloud's own
    a = atlas().build(disc)
    assert a.edge_pu_.max() <= MAX_EDGE_PU
