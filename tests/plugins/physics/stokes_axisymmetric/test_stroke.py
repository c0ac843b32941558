"""Strokes: periodicity, time reversal, the scallop theorem and the stroke integrals."""
import numpy as np
import pytest

from pointatlas.errors import InputError
from pointatlas_physics.stokes_axisymmetric.stroke import Discretisation, swim_stroke
from pointatlas_studies import meridian_motions as mm

DISC = Discretisation(24)


def test_a_stroke_that_does_not_close_is_refused():
    t, X, V = mm.small_amplitude_stroke(1.0, 65, 8, 0.05, {2: 1.0, 3: 1j}, {})
    X = X.copy()
    X[-1, 5:-5] *= 1.01
    with pytest.raises(InputError, match="not periodic"):
        swim_stroke(t, X, V, 1.0, DISC)


def test_times_must_increase_and_shapes_match():
    t, X, V = mm.small_amplitude_stroke(1.0, 65, 8, 0.05, {2: 1.0, 3: 1j}, {})
    with pytest.raises(InputError, match="increase strictly"):
        swim_stroke(t[::-1], X, V, 1.0, DISC)
    with pytest.raises(InputError, match="one shape and one velocity per time"):
        swim_stroke(t, X, V[:-1], 1.0, DISC)


def test_time_reversal_flips_the_net_displacement():
    eps = 0.08
    t, X, V = mm.small_amplitude_stroke(1.0, 65, 16, eps, {2: 1.0, 3: 1j}, {})
    fwd = swim_stroke(t, X, V, 1.0, DISC)
    back = swim_stroke(t, X[::-1], -V[::-1], 1.0, DISC)
    assert abs(fwd.position[-1]) > 1e-4
    assert back.position[-1] == pytest.approx(-fwd.position[-1], rel=1e-9)
    # powers are even under reversal, and the mean shape is the same
    assert back.mean_power_out == pytest.approx(fwd.mean_power_out, rel=1e-9)


def test_a_reciprocal_stroke_at_other_rates_goes_nowhere():
    t, X, V, s = mm.reciprocal_stroke(1.0, 65, 48, 0.3, 0.5, 0.5)
    sol = swim_stroke(t, X, V, 1.0, DISC)
    turn = int(np.argmax(s))
    assert abs(sol.position[turn]) > 1e-3 and abs(sol.angle[turn]) > 1e-3
    assert abs(sol.position[-1]) < 1e-6 * abs(sol.position[turn])
    assert abs(sol.angle[-1]) < 1e-6 * abs(sol.angle[turn])


def test_efficiency_of_a_steady_squirmer_stroke_is_one_half():
    """A 'stroke' of the steady B₁ squirmer (same shape and slip at every sample): Lighthill
    efficiency 6πμaŪ²/P̄ = ½ (Michelin & Lauga 2010: the optimum of tangential squirmers)."""
    nodes, v = mm.squirmer_slip(1.0, 129, 1.0, 0.0)
    t = np.linspace(0, 1, 5)
    sol = swim_stroke(t, np.repeat(nodes[None], 5, 0), np.repeat(v[None], 5, 0), 1.0,
                      Discretisation(64))
    assert sol.mean_speed == pytest.approx(2 / 3, rel=1e-5)
    assert sol.efficiency(sol.mean_power_out) == pytest.approx(0.5, rel=1e-4)


@pytest.mark.parametrize("radial, tangential", [
    ({2: 1.0}, {3: 1j}),                                # a radial and a tangential mode
    ({1: 0.5, 2: 1j}, {1: 0.3, 2: -0.4}),               # with first-order swimming
])
def test_small_amplitude_strokes_against_the_second_order_theory(radial, tangential):
    """X(T)/ε² of the boundary elements against ε² Ū₂ T of the reciprocal-theorem theory
    (pointatlas_studies.squirming_sphere_theory: Lamb's solution, an independent code)."""
    from pointatlas_studies.squirming_sphere_theory import second_order_mean_velocity

    eps = 0.01
    t, X, V = mm.small_amplitude_stroke(1.0, 129, 24, eps, radial, tangential)
    sol = swim_stroke(t, X, V, 1.0, Discretisation(48))
    theory = second_order_mean_velocity(radial, tangential, a=1.0, omega=2 * np.pi) * 1.0
    assert sol.position[-1] / eps ** 2 == pytest.approx(theory, rel=1e-3)
