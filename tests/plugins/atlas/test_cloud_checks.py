"""Components, creases and non-manifold points of clouds the project did not generate."""
import os

import numpy as np
import pytest
from pointatlas_atlas import cloud_checks as cc
from scipy.spatial import cKDTree


def pyvista_mesh_points(name):
    pv = pytest.importorskip("pyvista")
    from pyvista import examples

    return np.asarray(pv.read(os.path.join(os.path.dirname(examples.__file__), name)).points,
                      dtype=np.float64)


def fibonacci_sphere(n, radius=1.0, centre=(0.0, 0.0, 0.0)):
    """n quasi-uniform points on a sphere (golden-angle spiral)."""
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    phi = np.pi * (1 + 5 ** 0.5) * i
    r = np.sqrt(1 - z * z)
    return radius * np.c_[r * np.cos(phi), r * np.sin(phi), z] + np.asarray(centre)


def thin_out(X, r, rng):
    """Greedy Poisson-disc thinning: no two kept points closer than r."""
    tree, alive, keep = cKDTree(X), np.ones(len(X), bool), []
    for i in rng.permutation(len(X)):
        if alive[i]:
            keep.append(i)
            alive[tree.query_ball_point(X[i], r)] = False
    return X[np.sort(keep)]


def implicit_cloud(f, lo, hi, n_raw, spacing, seed):
    """Random points of a box projected by Newton steps onto f = 0 (central-difference
    gradient), thinned to a quasi-uniform cloud of the given spacing."""
    rng = np.random.default_rng(seed)
    X = rng.uniform(lo, hi, size=(n_raw, 3))
    e = 1e-6 * np.eye(3)
    for _ in range(40):
        g = np.stack([(f(X + e[i]) - f(X - e[i])) / 2e-6 for i in range(3)], axis=1)
        X = X - (f(X) / np.maximum((g * g).sum(1), 1e-300))[:, None] * g
    return thin_out(X[np.abs(f(X)) < 1e-10], spacing, rng)


def thin_torus(R=1.0, r=0.25):
    """Torus with about 25 spacings round its tube."""
    return implicit_cloud(lambda X: (np.hypot(X[:, 0], X[:, 1]) - R) ** 2 + X[:, 2] ** 2 - r * r,
                          -(R + r), R + r, 40_000, 0.06, seed=1)


def genus2_tube(r=0.13, delta=0.05):
    """A genus-2 surface: a tube of radius ~r about the figure-eight x²(1−x²) = y²
    (f = g²/(|∇g|² + δ) + z² − r²), 3 700 points, about 27 spacings round the tube."""
    def f(X):
        x, y, z = X.T
        g = x * x * (1 - x * x) - y * y
        return g * g / ((2 * x - 4 * x ** 3) ** 2 + 4 * y * y + delta) + z * z - r * r
    return implicit_cloud(f, [-1.3, -0.8, -1.2 * r], [1.3, 0.8, 1.2 * r], 90_000, 0.028, seed=2)


def cube_surface(n_side=20):
    """The surface of [−1, 1]³, an n_side × n_side grid on each face (cell centres)."""
    t = (np.arange(n_side) + 0.5) / n_side * 2 - 1
    u, v = (a.ravel() for a in np.meshgrid(t, t))
    faces = []
    for axis in range(3):
        others = [a for a in range(3) if a != axis]
        for side in (-1.0, 1.0):
            F = np.empty((u.size, 3))
            F[:, axis], F[:, others[0]], F[:, others[1]] = side, u, v
            faces.append(F)
    return np.concatenate(faces)


def t_junction(n=1500, seed=4):
    """Three half-planes meeting on the y axis: z = 0 (x < 0 and x > 0) and x = 0 (z > 0)."""
    rng = np.random.default_rng(seed)
    m = n // 3
    u, y = rng.uniform(0, 1, (3, m)), rng.uniform(-1, 1, (3, m))
    z = np.zeros(m)
    return np.concatenate([np.c_[-u[0], y[0], z], np.c_[u[1], y[1], z], np.c_[z, y[2], u[2]]])


def test_two_spheres_and_stray_points_are_two_components_and_isolated_points():
    rng = np.random.default_rng(0)
    stray = rng.uniform(-1, 1, (4, 3)) * 0.2 + [1.5, 3.0, 0.0]  # a clump of 4, far away
    P = np.concatenate([fibonacci_sphere(1200), fibonacci_sphere(800, 0.7, (3.0, 0, 0)), stray])
    comp = cc.cloud_components(P)
    assert comp.sizes.tolist() == [1200, 800]
    assert comp.n_isolated == 4 and (comp.labels[-4:] == -1).all()
    assert np.allclose(comp.centroids, [[0, 0, 0], [3, 0, 0]], atol=1e-2)
    check = cc.check_cloud(P)
    assert not check.crease.any() and not check.nonmanifold.any()
    assert cc.refusal(P, check) is None  # 4 of 2004 isolated: dropped, not refused


def test_random_sampling_is_one_component():
    """Poisson sampling: P(nearest neighbour > 5h) = 2^−25, no point is cut off."""
    X = np.random.default_rng(1).normal(size=(4000, 3))
    comp = cc.cloud_components(X / np.linalg.norm(X, axis=1)[:, None])
    assert comp.sizes.tolist() == [4000] and comp.n_isolated == 0


@pytest.mark.parametrize("cloud", ["sphere.ply", "thin torus", "genus-2 tube", "random sphere"])
def test_smooth_clouds_are_not_flagged(cloud):
    """pyvista's uneven 422-point sphere (integer coordinates), a torus and a genus-2 tube
    with ~25 spacings round: no crease, no non-manifold point (the nearest-neighbour normal
    jump reaches 42° on the genus-2 tube, so a 30° jump test would flag it)."""
    X = np.random.default_rng(3).normal(size=(3000, 3))
    P = {"sphere.ply": lambda: pyvista_mesh_points("sphere.ply"), "thin torus": thin_torus,
         "genus-2 tube": genus2_tube,
         "random sphere": lambda: X / np.linalg.norm(X, axis=1)[:, None]}[cloud]()
    check = cc.check_cloud(P)
    assert len(check.components.sizes) == 1 and check.components.n_isolated == 0
    assert check.crease.sum() == 0 and check.nonmanifold.sum() == 0
    assert cc.refusal(P, check) is None
    # the smooth residuals stay well below the threshold
    assert cc.quadric_residuals(P)[0].max() < 0.9 * cc.MAX_RESIDUAL


def test_cube_edges_are_creases():
    P = cube_surface(20)
    check = cc.check_cloud(P)
    # the two grid rows on either side of each of the 12 edges: 12 · 20 · 2 = 480 points
    dist_to_edge = np.sort(1 - np.abs(P), axis=1)[:, 1]
    assert check.crease.sum() == 480
    assert (dist_to_edge[check.crease] < 0.16).all()
    assert not check.nonmanifold.any()
    msg = cc.refusal(P, check)
    assert msg.startswith("this cloud has creases; the curvature integrals of a smooth atlas "
                          "do not apply there: 480 points on creases (of 2400)")
    assert "\n" not in msg


def test_nut_has_creases():
    P = pyvista_mesh_points("nut.ply")
    check = cc.check_cloud(P)
    assert check.crease.sum() > 0.5 * len(P)
    assert cc.refusal(P, check).startswith("this cloud has creases")


def test_t_junction_is_not_a_manifold_along_the_junction():
    P = t_junction()
    d = cc.surface_defects(P)
    nm = d.nonmanifold
    h = cc.median_spacing(P)
    dist_to_line = np.hypot(P[:, 0], P[:, 2])
    assert nm.sum() >= 30
    assert (dist_to_line[nm] < 4 * h).all()       # on the junction line, nowhere else
    assert not (d.crease | nm)[dist_to_line > 6 * h].any()
    assert "not a disc" in cc.defects_message(P, d.crease, nm, h)
    # without the third sheet the plane is smooth
    flat = P[P[:, 2] == 0]
    assert not cc.surface_defects(flat).nonmanifold.any()


def test_parallel_sheets_closer_than_the_spacing_are_not_a_manifold():
    rng = np.random.default_rng(5)
    a = np.c_[rng.uniform(-1, 1, (2, 1500)).T, np.zeros(1500)]
    b = np.c_[rng.uniform(-1, 1, (2, 1500)).T, np.full(1500, 0.02)]
    P = np.concatenate([a, b])
    d = cc.surface_defects(P)
    # nearly every point is rough; the pair-slope test sees the two sheets where two points lie
    # nearly above one another (12 % of them on this random sampling): refused either way
    assert (d.crease | d.nonmanifold).mean() > 0.9 and d.nonmanifold.sum() > 100
    assert "not a disc" in cc.refusal(P, cc.check_cloud(P))


def test_airplane_is_refused_as_too_unevenly_sampled():
    """airplane.ply's vertices crowd along the edges of a CAD mesh; its large flat
    triangles have none inside: over half the points are in small groups > 5h apart."""
    P = pyvista_mesh_points("airplane.ply")
    check = cc.check_cloud(P)
    assert check.components.n_isolated > 0.4 * len(P)
    assert cc.refusal(P, check).startswith("this cloud is too unevenly sampled")


def test_ant_is_refused():
    """ant.ply's 15 mesh pieces (legs, antennae, body) interpenetrate or touch: as a cloud
    one component whose legs cross the body, refused (creases and sheets meeting)."""
    P = pyvista_mesh_points("ant.ply")
    check = cc.check_cloud(P)
    assert check.nonmanifold.sum() > 100 and check.crease.sum() > 100
    assert "not a disc" in cc.refusal(P, check)


def test_where_names_far_apart_points():
    P = np.array([[0.0, 0, 0], [0.001, 0, 0], [1, 0, 0], [0, 2, 0]])
    assert cc.where(P, 2) == "(0, 0, 0), (0, 2, 0)"
