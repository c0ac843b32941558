"""Pressure loads on the atlas's one orientation (issue 16, item 7): a clamped circular plate
against Kirchhoff's w(0) = p a⁴ / (64 D), the refusal on an open surface whose side is not
fixed, outward normals on a closed sphere, a Möbius strip refused. The clouds are built
here (a sunflower disc with a boundary ring, a Fibonacci sphere), not by plugins/sources."""
import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError, InputError
from pointatlas.pointcloud import PointCloud
from pointatlas_atlas.settings import AtlasSettings
from pointatlas_physics.kirchhoff_love.analysis import (assemble_loads, build_model,
                                                        displacement_at, pressure_normals,
                                                        solve_linear)
from pointatlas_kit.selectors import Selector
from pointatlas_physics.kirchhoff_love.settings import Load, ShellSettings, Support

E, NU, H, A, P = 1.0e3, 0.3, 0.1, 1.0, 1.0
D = E * H**3 / (12 * (1 - NU**2))
W_KIRCHHOFF = P * A**4 / (64 * D)   # clamped circular plate, uniform load (Timoshenko §62)


def disc(n):
    """About n points in the disc r ≤ A: a ring of spacing h on r = A and Vogel's spiral
    inside r < A − h/2 (h = sqrt(π A² / n))."""
    h = np.sqrt(np.pi / n) * A
    m = int(round(2 * np.pi * A / h))
    t = 2 * np.pi * np.arange(m) / m
    i = np.arange(n - m) + 0.5
    r, s = (A - 0.5 * h) * np.sqrt(i / (n - m)), i * np.pi * (3 - np.sqrt(5))
    xy = np.vstack([np.column_stack([r * np.cos(s), r * np.sin(s)]),
                    A * np.column_stack([np.cos(t), np.sin(t)])])
    return np.column_stack([xy, np.zeros(len(xy))])


def fibonacci_sphere(n):
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    r, t = np.sqrt(1 - z * z), np.pi * (1 + np.sqrt(5)) * i
    return np.column_stack([r * np.cos(t), r * np.sin(t), z])


def shell(load, supports=None):
    return ShellSettings(
        young_modulus=E, poisson_ratio=NU, thickness=H, penalty=1e6,
        supports=supports if supports is not None else [
            Support(kind="clamped", where=Selector(expression=f"r > {0.999 * A}"))],
        loads=[load])


def model(points, settings, orientation=None):
    a = AtlasSettings(markers_per_patch=100, orientation=orientation)
    return build_model(
        PointCloud(points, name="test cloud"), settings, a,
        make_embedder=lambda: pointatlas.load_plugin("embedders", "pca")(n_components=2),
        make_lme=lambda: pointatlas.load_plugin("approximants", "lme")(
            gamma=a.gamma_lme, tol=a.tol_lme, outside="flag"),
        make_pu=lambda: pointatlas.load_plugin("approximants", "shepard")(
            gamma=a.gamma_pu, tol=a.tol_pu, outside="flag"))


def centre_deflections(n):
    """(w under pressure P with atlas.orientation = +z, w under the surface load P e_z, model)."""
    pressure = shell(Load(kind="pressure", pressure=P))
    m = model(disc(n), pressure, orientation=[0.0, 0.0, 1.0])
    assert m.atlas.orientation_ == "[0, 0, 1]"
    solve_linear(m, pressure)
    w_pressure = displacement_at(m, [0, 0, 0])[0][2]
    F_pressure = m.forces.copy()
    surface = shell(Load(kind="surface", force=[0.0, 0.0, P]))
    solve_linear(m, surface)
    np.testing.assert_allclose(F_pressure, m.forces, atol=1e-12 * np.abs(m.forces).max())
    return w_pressure, displacement_at(m, [0, 0, 0])[0][2], m


def test_clamped_disc_under_pressure_small():
    """500 points: −0.68 % (the bar at 2 000 points is the slow test below)."""
    w_p, w_s, m = centre_deflections(500)
    assert m.forces.sum(axis=0)[2] == pytest.approx(np.pi * A**2 * P, rel=0.01)
    assert w_p == pytest.approx(W_KIRCHHOFF, rel=0.015)   # today: −64 % (mixed normals)
    assert w_s == pytest.approx(w_p, rel=0.005)


@pytest.mark.slow
def test_clamped_disc_under_pressure_at_2000_points():
    """The issue's bar: within 0.5 % of p a⁴ / (64 D) (measured −0.39 %)."""
    w_p, w_s, _ = centre_deflections(2000)
    assert w_p == pytest.approx(W_KIRCHHOFF, rel=0.005)
    assert w_s == pytest.approx(w_p, rel=0.005)


def test_pressure_on_open_surface_without_orientation_is_refused():
    s = shell(Load(kind="pressure", pressure=P))
    m = model(disc(300), s)
    assert m.atlas.orientation_ == "first_chart"
    with pytest.raises(ConfigError, match=r"open surface.*atlas\.orientation=\["):
        assemble_loads(m, s)
    # the surface load needs no normal
    f = assemble_loads(m, shell(Load(kind="surface", force=[0, 0, -2.0])))
    assert f.sum(axis=0)[2] == pytest.approx(-2.0 * np.pi * A**2, rel=0.02)


def test_pressure_on_closed_sphere_pushes_outwards_without_orientation():
    s = shell(Load(kind="pressure", pressure=2.0),
              supports=[Support(kind="fixed", components=[0, 1, 2],
                                where=Selector(box=[-2, -2, 0.99, 2, 2, 2]))])
    m = model(fibonacci_sphere(700), s)
    assert not m.boundary.any() and m.atlas.orientation_ == "outward"
    F = assemble_loads(m, s)
    assert np.abs(F.sum(axis=0)).max() < 1e-3 * 2.0 * 4 * np.pi   # ∮ p n dA = 0
    # the virtual work of a uniform inflation u = x: ∮ p n·x dA = 3 p V = 4π p
    assert np.sum(F * m.nodes) == pytest.approx(2.0 * 4 * np.pi, rel=0.02)
    # every quadrature normal points away from the centre
    q = m.quadrature
    rows = np.repeat(np.arange(len(q.weights)), np.diff(q.indptr))
    x = np.stack([np.bincount(rows, q.basis[:, 0] * m.nodes[q.indices, j], len(q.weights))
                  for j in range(3)], axis=1)
    assert (np.einsum("ij,ij->i", pressure_normals(m), x) > 0.9).all()


def test_pressure_on_mobius_strip_is_refused():
    u = np.linspace(0, 2 * np.pi, 120, endpoint=False)
    U, V = np.meshgrid(u, np.linspace(-0.3, 0.3, 10), indexing="ij")
    U = U.ravel() + (np.arange(U.size) % 2) * np.pi / 120
    V = V.ravel()
    rho = 1 + V * np.cos(U / 2)
    points = np.column_stack([rho * np.cos(U), rho * np.sin(U), V * np.sin(U / 2)])
    s = shell(Load(kind="pressure", pressure=P),
              supports=[Support(kind="clamped", where=Selector(box=[0.5, -0.2, -1, 2, 0.2, 1]))])
    m = model(points, s, orientation=[0.0, 0.0, 1.0])
    assert not m.atlas.orientable_
    with pytest.raises(InputError, match="pressure load needs a normal.*not orientable"):
        assemble_loads(m, s)
