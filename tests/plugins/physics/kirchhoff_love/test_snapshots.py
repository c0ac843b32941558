"""Energy density at the sampled points (analytic plate states) and the snapshot picture."""
import io

import numpy as np
import pytest

from pointatlas.errors import InputError
from pointatlas_physics.kirchhoff_love.snapshots import point_energy_operator
from pointatlas_studies.shell_figures import pick_snapshots, snapshot_figure


@pytest.fixture(scope="module")
def plate(quarter_plate):
    """(model, point energy operator) of the flat 5 × 5 quarter plate in z = 0."""
    _, model = quarter_plate
    return model, point_energy_operator(model)


def _rotation(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def _interior(model, margin=0.8):
    """Sampled points at least ``margin`` from the plate edges (x, y in [0, 5])."""
    P = model.points
    return np.all((P[:, :2] > margin) & (P[:, :2] < 5.0 - margin), axis=1)


def test_zero_at_rest_and_for_a_rigid_motion(plate):
    model, op = plate
    X = model.nodes
    assert op.n_undefined == 0
    np.testing.assert_array_equal(op(np.zeros_like(X)), 0.0)
    R = _rotation([1.0, 2.0, -0.5], 0.9)  # a finite rotation (~52°) and a translation
    U_rigid = X @ (R - np.eye(3)).T + np.array([0.3, -1.2, 2.0])
    w_rigid = op(U_rigid)
    U_def = np.column_stack([0.01 * X[:, 0], 0.0 * X[:, 1], 0.02 * X[:, 0] ** 2])
    scale = np.abs(op(U_def)).max()
    assert scale > 0
    assert np.abs(w_rigid).max() < 1e-8 * scale
    # the rigid motion superposed on a deformation leaves the density unchanged
    U_both = (X + U_def) @ R.T + np.array([0.3, -1.2, 2.0]) - X
    np.testing.assert_allclose(op(U_both), op(U_def), rtol=1e-7, atol=1e-8 * scale)


def test_uniform_stretch_matches_saint_venant_kirchhoff(plate):
    model, op = plate
    mat = model.material
    E, nu, h = mat.young_modulus, mat.poisson_ratio, mat.thickness
    F = np.array([[1.04, 0.015], [-0.01, 0.97]])  # in-plane deformation gradient
    X = model.nodes
    U = np.zeros_like(X)
    U[:, :2] = X[:, :2] @ (F - np.eye(2)).T
    G = 0.5 * (F.T @ F - np.eye(2))                 # Green strain
    e = np.array([G[0, 0], G[1, 1], 2 * G[0, 1]])
    D = E / (1 - nu ** 2) * np.array([[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]])
    w_m = 0.5 * h * e @ D @ e
    w = op(U)
    np.testing.assert_allclose(w[:, 0], w_m, rtol=1e-7)
    assert np.abs(w[:, 1]).max() < 1e-12 * w_m
    np.testing.assert_allclose(w[:, 2], w[:, 0] + w[:, 1])


def test_cylindrical_bending_is_inextensional(plate):
    """Roll the plate onto a cylinder of radius R about the y axis: κ_11 = 1/R, no stretch,
    so w_b = ½ E h³/(12(1−ν²)) / R² and w_m ≈ 0 (up to the approximation error)."""
    model, op = plate
    mat = model.material
    R = 8.0
    X = model.nodes
    t = X[:, 0] / R
    x = np.column_stack([R * np.sin(t), X[:, 1], R * (1 - np.cos(t))])
    w = op(x - X)
    w_b = 0.5 * mat.bending_rigidity / R ** 2
    inner = _interior(model)
    assert inner.sum() > 20
    # LME reproduces linear fields only: its second derivatives of x² carry a small uniform
    # bias on this grid (+0.2 % in κ, +0.4 % in w_b)
    np.testing.assert_allclose(w[inner, 1], w_b, rtol=1e-2)
    assert np.abs(w[:, 1] / w_b - 1).max() < 0.2   # edge points: one-sided LME derivatives
    # membrane: the O(spacing²/R²) metric error of the LME chart derivatives (|ε| ≈ 7e-4)
    # weighs 12 R²/h² times more than curvature errors; still far below the bending energy
    assert np.abs(w[inner, 0]).max() < 0.1 * w_b


def test_operator_rejects_wrong_shapes(plate):
    model, op = plate
    with pytest.raises(InputError, match="shape"):
        op(np.zeros((model.nodes.shape[0] + 1, 3)))


def test_pick_snapshots():
    assert pick_snapshots(10, 4) == [2, 4, 7, 9]
    assert pick_snapshots(20) == [4, 9, 14, 19]
    assert pick_snapshots(3, 4) == [0, 1, 2]
    assert pick_snapshots(7, 1) == [6]
    for n in range(1, 30):
        for k in range(1, 6):
            idx = pick_snapshots(n, k)
            assert idx[-1] == n - 1 and len(idx) == min(n, k)
            assert idx == sorted(set(idx)) and idx[0] >= 0
    with pytest.raises(InputError, match="n_increments"):
        pick_snapshots(0)
    with pytest.raises(InputError, match="k = 0"):
        pick_snapshots(5, 0)


def test_snapshot_figure_is_a_png_with_content(plate):
    import matplotlib.image as mpimg

    model, op = plate
    X = model.points
    shapes = [np.column_stack([0 * X[:, 0], 0 * X[:, 1], -c * (25 - X[:, 0] ** 2 - X[:, 1] ** 2)
                               / 25]) for c in (0.2, 0.5, 1.0, 1.5)]
    nodes_u = [np.vstack([u, np.zeros((model.n_ghosts, 3))]) for u in shapes]
    dens = [op(U) for U in nodes_u]
    png = snapshot_figure(X, shapes, dens, [f"step {i}" for i in range(4)], window=(500, 400))
    assert png[:4] == b"\x89PNG"
    img = mpimg.imread(io.BytesIO(png))
    assert img.shape[:2] == (400, 500)
    assert np.unique(img.reshape(-1, img.shape[-1]), axis=0).shape[0] > 20
    png2 = snapshot_figure(X, shapes[:2], [d[:, 2] for d in dens[:2]], ["a", "b"],
                           window=(400, 200), log_scale=False)
    assert png2[:4] == b"\x89PNG"
    with pytest.raises(InputError, match="1 to 4"):
        snapshot_figure(X, shapes + shapes[:1], dens + dens[:1], list("abcde"))


@pytest.fixture(scope="module")
def hemisphere():
    """(model, operator) of a coarse quarter of the open hemisphere (radius 10, 3 charts)."""
    import pointatlas
    from pointatlas_atlas.settings import AtlasSettings
    from pointatlas_physics.kirchhoff_love.analysis import build_model
    from pointatlas_physics.kirchhoff_love.settings import ShellSettings

    cloud = pointatlas.load_plugin("sources", "hemisphere")(
        n_points=300, model="quarter", hole_angle_deg=18.0).load(np.random.default_rng(0))
    model = build_model(
        cloud, ShellSettings(young_modulus=6.825e7, poisson_ratio=0.3, thickness=0.04),
        AtlasSettings(n_patches=3, quadrature_order=4),  # 3 charts, whatever the repair keeps
        make_embedder=lambda: pointatlas.load_plugin("embedders", "pca")(n_components=2),
        make_lme=lambda: pointatlas.load_plugin("approximants", "lme")(gamma=0.8, tol=1e-8,
                                                                      outside="flag"),
        make_pu=lambda: pointatlas.load_plugin("approximants", "shepard")(gamma=4.0, tol=1e-6,
                                                                         outside="flag"))
    return model, point_energy_operator(model)


def _per_chart(model, motion):
    """Yield (points of chart κ, U) with U_a = motion(C_a^κ) on the control points of κ.

    A curved chart is φ_κ = Σ p_a C_a^κ with refitted control points C^κ ≠ x_a, so a motion
    of the surface is exact in one chart only when applied to that chart's C^κ."""
    from pointatlas_atlas.evaluation import node_charts

    chart, _ = node_charts(model.atlas, np.arange(model.points.shape[0]))
    for k, c in enumerate(model.atlas.charts_):
        U = np.zeros_like(model.nodes)
        U[c.node_index] = motion(c.control_points) - c.control_points
        yield chart == k, U


def test_curved_shell_rigid_motion_and_uniform_dilation(hemisphere):
    """Sphere x = s X: ε_αβ = ½(s²−1) A_αβ and κ_αβ = (1−s) B_αβ, B_αβ = A_αβ/R, so
    w_m = ½ h ((s²−1)/2)² 2E/(1−ν) and w_b = ½ h³/12 ((1−s)/R)² 2E/(1−ν)."""
    model, op = hemisphere
    mat = model.material
    E, nu, h, radius, s = mat.young_modulus, mat.poisson_ratio, mat.thickness, 10.0, 1.01
    assert len(model.atlas.charts_) >= 2 and op.n_undefined == 0
    w_m = 0.5 * h * ((s * s - 1) / 2) ** 2 * 2 * E / (1 - nu)
    w_b = 0.5 * h ** 3 / 12 * ((1 - s) / radius) ** 2 * 2 * E / (1 - nu)
    R = _rotation([0.3, -1.0, 2.0], 1.3)
    seen = np.zeros(model.points.shape[0], bool)
    for sel, U in _per_chart(model, lambda C: C @ R.T + np.array([1.0, 2.0, -3.0])):
        assert np.abs(op(U)[sel]).max() < 1e-8 * w_m
        seen |= sel
    assert seen.all()
    for sel, U in _per_chart(model, lambda C: s * C):
        w = op(U)[sel]
        np.testing.assert_allclose(w[:, 0], w_m, rtol=1e-8)
        assert np.median(np.abs(w[:, 1] / w_b - 1)) < 0.03  # LME chart curvature error
