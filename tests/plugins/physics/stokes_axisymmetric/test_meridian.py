"""Generating curves: what is refused (one line naming the fix) and the spline's accuracy."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pointatlas.errors import InputError
from pointatlas_physics.stokes_axisymmetric.meridian import Meridian, check_meridian


def circle(n=65, R=1.0):
    th = np.linspace(0, np.pi, n)
    return np.column_stack([R * np.sin(th), R * np.cos(th)])


@pytest.mark.parametrize("make, message", [
    (lambda P: P[:4], "need at least 5"),
    (lambda P: P[1:], "does not start on the axis"),
    (lambda P: P[:-1], "does not end on the axis"),
    (lambda P: P[::-1], "reverse the node order"),
    (lambda P: np.insert(P, 3, P[3], axis=0), "coincide"),
    (lambda P: np.where(np.arange(len(P))[:, None] == 30, [-0.2, P[30, 1]], P), "crosses the axis"),
    (lambda P: np.vstack([P[:40], P[[20]] + [0.05, 0.0], P[40:]]), "crosses itself"),
    (lambda P: np.where(np.arange(len(P))[:, None] == 7, np.nan, P), "non-finite"),
    (lambda P: P[:, :1], "(n, 2) array"),
])
def test_bad_curves_are_refused_with_the_fix(make, message):
    with pytest.raises(InputError, match=message.replace("(", r"\(").replace(")", r"\)")):
        check_meridian(make(circle()))


def test_a_curve_ending_just_off_the_axis_is_snapped_onto_it():
    P = circle()
    P[0, 0] = 1e-9
    assert check_meridian(P)[0, 0] == 0.0


def test_spline_geometry_and_normals_on_a_circle():
    m = Meridian(circle(33))
    t = np.linspace(0, 1, 1001)
    x = m.point(t)
    assert np.abs(np.hypot(x[:, 0], x[:, 1]) - 1).max() < 1e-5
    n = m.normal(t)
    np.testing.assert_allclose(n, x / np.linalg.norm(x, axis=1)[:, None], atol=5e-4)
    # mirror symmetry: r odd and z even about both poles
    eps = np.array([1e-3, 1e-2])
    np.testing.assert_allclose(m.point(-eps)[:, 0], -m.point(eps)[:, 0], rtol=1e-12)
    np.testing.assert_allclose(m.point(1 + eps)[:, 1], m.point(1 - eps)[:, 1], rtol=1e-12)


def test_spline_converges_at_fourth_order():
    errs = []
    for n in (17, 33, 65):
        x = Meridian(circle(n)).point(np.linspace(0, 1, 2001))
        errs.append(np.abs(np.hypot(x[:, 0], x[:, 1]) - 1).max())
    assert errs[0] / errs[1] > 12 and errs[1] / errs[2] > 12


def test_nodal_fields_need_one_value_per_node():
    m = Meridian(circle())
    with pytest.raises(InputError, match="one per node"):
        m.field(np.zeros((10, 3)), (-1, 1, -1))


def _first_crossing_by_pairs(P):
    """Segment pairs one by one, scalar arithmetic: the reference for the block search."""
    def cross(o, p, q):
        return (p[0] - o[0]) * (q[1] - o[1]) - (p[1] - o[1]) * (q[0] - o[0])
    for i in range(len(P) - 3):
        for j in range(i + 2, len(P) - 1):
            a, b, c, d = P[i], P[i + 1], P[j], P[j + 1]
            if cross(c, d, a) * cross(c, d, b) < 0 and cross(a, b, c) * cross(a, b, d) < 0:
                return i, j
    return None


@settings(max_examples=60, deadline=None)
@given(n=st.integers(3, 40), seed=st.integers(0, 2**31), wiggle=st.floats(0.0, 0.3),
       block=st.sampled_from([1, 5, 1 << 21]))
def test_the_self_crossing_search_finds_the_first_crossing_pair(n, seed, wiggle, block):
    from pointatlas_physics.stokes_axisymmetric.meridian import _segments_cross

    P = circle(n) + np.random.default_rng(seed).normal(scale=wiggle, size=(n, 2))
    assert _segments_cross(P, block) == _first_crossing_by_pairs(P)
