"""One orientation for the whole atlas, on clouds not made by the project's sources: a
sunflower disc, a Fibonacci hemisphere, pyvista's spheres, a Möbius strip and its untwisted
band (issue 16, item 3)."""
import numpy as np
import pytest

from pointatlas.errors import ConfigError, InputError
from pointatlas_atlas.atlas import AtlasSettings
from pointatlas_atlas.orientation import frame_vectors, orient_charts

from .test_atlas import make_atlas




def rotation(seed=0):
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def sunflower_disc(n):
    """Vogel's spiral: n quasi-uniform points in the unit disc of the plane z = 0."""
    i = np.arange(n) + 0.5
    r, t = np.sqrt(i / n), i * np.pi * (3 - np.sqrt(5))
    return np.column_stack([r * np.cos(t), r * np.sin(t), np.zeros(n)])


def fibonacci_cap(n, z_min=0.0):
    """n quasi-uniform points on the unit sphere above z = z_min (Fibonacci lattice)."""
    i = np.arange(n) + 0.5
    z = 1.0 - (1.0 - z_min) * i / n
    r, t = np.sqrt(1 - z * z), np.pi * (1 + np.sqrt(5)) * i
    return np.column_stack([r * np.cos(t), r * np.sin(t), z])


def strip(twist, n_u=120, n_v=10, width=0.3):
    """A band round the unit circle, width 2·width: twist=0.5 a Möbius strip, 0 a cylinder."""
    u = np.linspace(0, 2 * np.pi, n_u, endpoint=False)
    U, V = np.meshgrid(u, np.linspace(-width, width, n_v), indexing="ij")
    U = U.ravel() + (np.arange(U.size) % 2) * np.pi / n_u   # staggered rows
    V = V.ravel()
    rho = 1 + V * np.cos(twist * U)
    return np.column_stack([rho * np.cos(U), rho * np.sin(U), V * np.sin(twist * U)])


def per_chart_side(qp, reference):
    """(L,) median sign of n·reference over each chart's quadrature points."""
    c = np.sign(np.einsum("ij,ij->i", qp.geometry["normal"], reference))
    return np.array([np.median(c[qp.chart == k]) for k in np.unique(qp.chart)])


def test_frame_vectors_are_the_unit_normal_of_a_surface():
    T = np.random.default_rng(1).normal(size=(50, 2, 3))
    n = np.cross(T[:, 0], T[:, 1])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    W = frame_vectors(T)
    # Plücker coordinates (x∧y, x∧z, y∧z) = (n_z, −n_y, n_x): the same dot products
    np.testing.assert_allclose(W @ W.T, n @ n.T, atol=1e-12)


def test_charts_flipped_along_overlaps_and_odd_cycle_detected():
    """Three charts on a chain share points pairwise; chart 2 is flipped relative to 1."""
    up = np.array([[0.0, 0.0, 1.0]])
    nodes = [np.arange(0, 10), np.arange(5, 15), np.arange(10, 20)]
    frames = [np.repeat(up, 10, 0), np.repeat(up, 10, 0), np.repeat(-up, 10, 0)]
    o = orient_charts(nodes, frames, 20)
    assert o.orientable and o.n_overlaps == 2 and o.mode == "first_chart"
    np.testing.assert_array_equal(o.signs, [1, 1, -1])
    # close the chain into a ring whose last overlap disagrees: no sign choice fixes it
    nodes.append(np.r_[np.arange(15, 20), np.arange(0, 5)])
    frames.append(np.r_[np.repeat(-up, 5, 0), np.repeat(-up, 5, 0)])
    o = orient_charts(nodes, frames, 20)
    assert o.orientable and o.n_overlaps == 4
    frames[3] = np.r_[np.repeat(-up, 5, 0), np.repeat(up, 5, 0)]  # a half twist
    nodes[3] = np.r_[np.arange(15, 20), np.arange(0, 5)]
    o = orient_charts([nodes[0], nodes[2], nodes[3]], [frames[0], frames[2], frames[3]], 20)
    assert o.orientable  # 0–2 share nothing: a chain, still orientable
    o = orient_charts(nodes, frames, 20)
    assert not o.orientable and o.n_conflicts >= 1 and o.mode == "none"


@pytest.fixture(scope="module")
def disc():
    return sunflower_disc(800) @ rotation(2).T


def test_open_disc_has_one_side_and_follows_the_given_direction(disc):
    e = rotation(2)[:, 2]                    # the disc's normal after the rotation
    atlas = make_atlas().build(disc)
    assert len(atlas.charts_) > 3 and atlas.orientable_
    assert atlas.orientation_ == "first_chart"
    n = atlas.quadrature_points().geometry["normal"]
    side = np.sign(n @ e)
    assert (side == side[0]).all()           # today: charts of both signs
    for want in (e, -e, -e + 0.5 * rotation(2)[:, 0]):
        atlas = make_atlas(orientation=list(want)).build(disc)
        qp = atlas.quadrature_points()
        assert (qp.geometry["normal"] @ want > 0).all()
        assert atlas.orientation_.startswith("[")
        assert np.all(atlas.chart_orientation_ ** 2 == 1)


def test_direction_along_the_disc_is_refused(disc):
    with pytest.raises(InputError, match="atlas.orientation.*tangent"):
        make_atlas(orientation=list(rotation(2)[:, 0])).build(disc)


def test_bad_orientation_setting_is_refused():
    with pytest.raises(ConfigError, match="orientation"):
        AtlasSettings(orientation=[0.0, 0.0, 0.0]).check()


def test_open_hemisphere_follows_direction_and_mean_curvature_has_one_sign():
    P = fibonacci_cap(900)
    for e, outward in (([0, 0, 1], 1), ([0.2, 0, -1], -1)):
        atlas = make_atlas(orientation=e).build(P)
        qp = atlas.quadrature_points()
        radial = qp.positions / np.linalg.norm(qp.positions, axis=1, keepdims=True)
        assert (outward * np.einsum("ij,ij->i", qp.geometry["normal"], radial) > 0.5).all()
        # H = tr(a⁻¹b), b = φ_αβ·n: −2 on the unit sphere with outward n (thesis convention)
        H = qp.geometry["mean_curvature"]
        assert np.median(H) == pytest.approx(-2.0 * outward, rel=0.02)
        assert (outward * H < 0).mean() > 0.99


@pytest.mark.parametrize("name", ["pv_sphere", "sphere_ply"])
def test_closed_sphere_gets_outward_normals(name):
    """pyvista's Sphere mesh (radius 0.5) and its bundled, unevenly sampled sphere.ply."""
    pyvista = pytest.importorskip("pyvista")
    from pyvista import examples

    mesh = pyvista.Sphere() if name == "pv_sphere" else pyvista.read(examples.spherefile)
    P = np.asarray(mesh.clean().points, dtype=np.float64)
    P = P - P.mean(axis=0)
    R = float(np.linalg.norm(P, axis=1).mean())
    # a direction given for a closed surface does not override "outward"
    atlas = make_atlas(orientation=[0.0, 0.0, -1.0]).build(P)
    assert atlas.orientation_ == "outward" and atlas.orientable_
    qp = atlas.quadrature_points()
    n, w, x = qp.geometry["normal"], qp.weights, qp.positions
    assert (per_chart_side(qp, x) == 1).all()
    assert (np.einsum("ij,ij->i", n, x) > 0).mean() > 0.999
    volume = w @ np.einsum("ij,ij->i", x, n) / 3                 # ∫ x·n dA / 3
    assert volume == pytest.approx(4 / 3 * np.pi * R**3, rel=0.03)
    # ∫ H dA = −8πR with outward normals; ∫ K dA and Willmore do not depend on the sign
    assert w @ qp.geometry["mean_curvature"] == pytest.approx(-8 * np.pi * R, rel=0.05)
    assert w @ qp.geometry["gaussian_curvature"] == pytest.approx(4 * np.pi, rel=0.05)


def test_mobius_strip_is_not_orientable_and_signed_quantities_are_refused():
    band = make_atlas().build(strip(twist=0.0))
    assert band.orientable_ and band.orientation_report_.n_conflicts == 0
    atlas = make_atlas().build(strip(twist=0.5))
    assert not atlas.orientable_ and atlas.orientation_ == "none"
    assert atlas.orientation_report_.n_conflicts >= 1
    qp = atlas.quadrature_points()
    for key in ("normal", "mean_curvature", "second_fundamental_form", "principal_curvatures"):
        with pytest.raises(InputError, match="not orientable"):
            qp.geometry[key]
    # orientation-free quantities still work, and agree with the untwisted band's shape
    area = float(qp.weights.sum())
    assert area == pytest.approx(float(band.quadrature_points().weights.sum()), rel=0.05)
    assert np.isfinite(qp.geometry["gaussian_curvature"]).all()
    H2 = qp.geometry["mean_curvature_squared"]
    assert np.isfinite(H2).all() and np.median(H2) > 0
