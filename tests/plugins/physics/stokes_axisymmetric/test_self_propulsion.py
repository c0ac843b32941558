"""Towed, spun and self-propelled bodies against closed-form Stokes solutions."""
import numpy as np
import pytest

from pointatlas.errors import InputError
from pointatlas_physics.stokes_axisymmetric.stroke import (Discretisation, drag_per_speed,
                                                          solve_one)

MU = 1.7


def spheroid(a=1.0, aspect=1.0, n=129):
    th = np.linspace(0, np.pi, n)
    return np.column_stack([a * np.sin(th), aspect * a * np.cos(th)])


def rigid(nodes, U=0.0, Om=0.0):
    v = np.zeros((len(nodes), 3))
    v[:, 1], v[:, 2] = U, Om * nodes[:, 0]
    return v


def slip(nodes, B1, B2):
    th = np.arccos(np.clip(nodes[:, 1], -1, 1))
    ut = B1 * np.sin(th) + B2 * np.sin(th) * np.cos(th)
    return np.column_stack([ut * np.cos(th), -ut * np.sin(th), 0 * th])


def test_towed_sphere_drag_and_power_at_64_elements():
    a, U = 0.8, 1.3
    el, s = solve_one(spheroid(a), rigid(spheroid(a), U=U), MU, Discretisation(64), free=False)
    F = 6 * np.pi * MU * a * U
    assert s.force == pytest.approx(F, rel=1e-6)
    assert s.power_out == pytest.approx(F * U, rel=1e-6)
    assert s.power_total == pytest.approx(F * U, rel=1e-6)
    # the traction of a towed sphere is uniform, 3μU/(2a) along the axis
    np.testing.assert_allclose(s.traction[:, 1], 1.5 * MU * U / a, rtol=1e-6)


def test_spun_sphere_torque_and_power():
    a, Om = 1.2, 0.7
    nodes = spheroid(a)
    _, s = solve_one(nodes, rigid(nodes, Om=Om), MU, Discretisation(64), free=False)
    T = 8 * np.pi * MU * a ** 3 * Om
    assert s.torque == pytest.approx(T, rel=1e-5)
    assert s.power_out == pytest.approx(T * Om, rel=1e-5)


@pytest.mark.parametrize("aspect", [0.3, 0.5, 2.0, 4.0])
def test_towed_spheroids_against_happel_and_brenner(aspect):
    """Independent closed forms (prolate and oblate spheroids along their axis)."""
    from pointatlas_studies.stokes_swimming import spheroid_drag

    F = drag_per_speed(spheroid(1.0, aspect, 257), MU, Discretisation(96, element_spacing="cosine"))
    assert F == pytest.approx(spheroid_drag(MU, 1.0, aspect, 1.0), rel=2e-4)


def test_rigid_motion_has_equal_exterior_and_total_tractions():
    """The interior of a rigidly moving body is at rest relative to it: f_inn = 0 (up to the
    pressure gauge), so the double-layer route to f_out gives the single-layer total."""
    nodes = spheroid(1.0, 1.6)
    _, s = solve_one(nodes, rigid(nodes, U=0.4, Om=-1.1), MU, Discretisation(64), free=False)
    np.testing.assert_allclose(s.traction_out, s.traction, atol=2e-4 * np.abs(s.traction).max())


@pytest.mark.parametrize("B2", [0.0, 0.7, -1.5])
def test_squirmer_speed_and_exterior_power(B2):
    B1 = 1.0
    nodes = spheroid(1.0, 1.0, 257)
    _, s = solve_one(nodes, slip(nodes, B1, B2), MU, Discretisation(64))
    assert s.translation == pytest.approx(2 * B1 / 3, rel=1e-5)
    assert s.power_out == pytest.approx(16 * np.pi / 3 * MU * (B1 ** 2 + B2 ** 2 / 2), rel=1e-4)
    assert s.power_total > s.power_out
    assert abs(s.force) < 1e-10 and abs(s.gauge) < 1e-4


def test_a_free_body_given_a_rigid_translation_cancels_it():
    nodes = spheroid(1.0, 1.4)
    _, s = solve_one(nodes, rigid(nodes, U=0.9, Om=0.3), MU, Discretisation(48))
    assert s.translation == pytest.approx(-0.9, rel=1e-10)
    assert s.rotation == pytest.approx(-0.3, rel=1e-10)
    assert abs(s.power_out) < 1e-8 and abs(s.power_total) < 1e-8


def test_breathing_is_removed_by_the_permeation_velocity():
    nodes = spheroid(1.0, 1.0)
    v = np.zeros((len(nodes), 3))
    v[:, :2] = 0.2 * nodes                       # radial expansion of the unit sphere
    _, s = solve_one(nodes, v, MU, Discretisation(32))
    S = 4 * np.pi
    assert s.volume_rate == pytest.approx(0.2 * S, rel=1e-6)
    assert s.permeation == pytest.approx(-0.2, rel=1e-6)
    assert abs(s.translation) < 1e-10 and abs(s.power_total) < 1e-8


def test_a_wrong_velocity_array_is_refused():
    nodes = spheroid()
    with pytest.raises(InputError, match=r"give \(v_r, v_z, v_φ\) at each"):
        solve_one(nodes, np.zeros((len(nodes), 2)), MU, Discretisation(16))


def test_a_generating_curve_given_as_a_bspline():
    """A user's B-spline (scipy's own interpolant of an ellipse, not this code's splines):
    the same drag as the points it was built from."""
    from scipy.interpolate import make_interp_spline

    th = np.linspace(0, np.pi, 41)
    P = np.column_stack([np.sin(th), 2.0 * np.cos(th)])
    curve = make_interp_spline(th, P, k=3)
    vel = make_interp_spline(th, rigid(P, U=1.0), k=3)
    _, s = solve_one(curve, vel, MU, Discretisation(64), free=False)
    from pointatlas_studies.stokes_swimming import spheroid_drag

    assert s.force == pytest.approx(spheroid_drag(MU, 1.0, 2.0, 1.0), rel=1e-4)
