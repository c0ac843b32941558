"""Boundary/region selectors written in YAML without code."""
import dataclasses

import numpy as np
import pytest

import pointatlas
from pointatlas.errors import ConfigError, InputError
from pointatlas_atlas.boundary import boundary_curves, boundary_mask
from pointatlas_kit.selectors import (Selector, describe,
                                                         evaluate_expression, select)


@pytest.fixture(scope="module")
def plate():
    X = pointatlas.load_plugin("sources", "square_plate")(n_points=441).load(
        np.random.default_rng(0)).points
    mask = boundary_mask(X)
    return X, mask, boundary_curves(X, mask)


@pytest.fixture(scope="module")
def open_hemisphere():
    X = pointatlas.load_plugin("sources", "hemisphere")(n_points=800, hole_angle_deg=18.0).load(
        np.random.default_rng(0)).points
    mask = boundary_mask(X)
    return X, mask, boundary_curves(X, mask)


def test_plane_box_expression_and_their_conjunction(plate):
    X, mask, curves = plate
    edge = select(Selector(plane=[1, 0, 0, 5]), X, mask, curves)
    np.testing.assert_array_equal(edge, np.flatnonzero(np.isclose(X[:, 0], 5)))
    assert np.all(np.diff(edge) > 0)
    same = select(Selector(expression="abs(x - 5) < 1e-6"), X, mask, curves)
    np.testing.assert_array_equal(edge, same)
    upper = select(Selector(plane=[2, 0, 0, 10], expression="y > 0"), X, mask, curves)
    np.testing.assert_array_equal(upper, edge[X[edge, 1] > 0])
    box = select(Selector(box=[-0.1, -0.1, -1, 0.1, 0.1, 1], on_boundary=False), X, mask, curves)
    assert box.tolist() == [int(np.argmin(np.linalg.norm(X, axis=1)))]  # the centre
    everything = select(Selector(expression="x == x", on_boundary=False), X, mask, curves)
    assert len(everything) == len(X)


def test_chained_comparisons_functions_and_logic():
    X = np.array([[0.0, 0, 0], [1, 0, 0], [0, 2, 0], [3, 4, 12]])
    np.testing.assert_array_equal(evaluate_expression("0.5 < rho <= 2", X), [0, 1, 1, 0])
    np.testing.assert_array_equal(evaluate_expression("r == 13 or not x < 1", X), [0, 1, 0, 1])
    np.testing.assert_array_equal(
        evaluate_expression("sqrt(x**2 + y**2) > 4.9 and arctan2(y, x) < pi/2", X), [0, 0, 0, 1])
    np.testing.assert_array_equal(evaluate_expression("abs(sin(phi)) > 0.5 and -z < 0", X),
                                  [0, 0, 0, 1])


@pytest.mark.parametrize("expression, token", [
    ("__import__('os').system('ls')", "__import__"), ("x.real > 0", "Attribute"),
    ("open('f') or x > 0", "open"), ("q > 0", "'q'"), ("x if y else z", "IfExp"),
    ("[x][0] > 1", "Subscript"), ("'a' == x", "'a'"), ("(lambda: x)() > 0", "lambda"),
    ("[v for v in x] > 0", "ListComp"), ("x @ y > 0", "MatMult"), ("~x > 0", "Invert"),
])
def test_forbidden_expressions_name_the_token_and_the_allowed_names(expression, token):
    with pytest.raises(ConfigError, match="Allowed") as info:
        evaluate_expression(expression, np.zeros((3, 3)))
    assert token in str(info.value) and "rho" in str(info.value)


def test_syntax_and_non_boolean_expressions():
    with pytest.raises(ConfigError, match="syntax"):
        evaluate_expression("x >", np.zeros((2, 3)))
    with pytest.raises(ConfigError, match="true/false"):
        evaluate_expression("x + 1", np.zeros((2, 3)))
    assert not evaluate_expression("9**9**9 < x", np.zeros((2, 3))).any()  # no huge integers


def test_nearest_curve_picks_the_hole_or_the_equator(open_hemisphere):
    X, mask, curves = open_hemisphere
    hole = select(Selector(nearest_curve=[0, 0, 10]), X, mask, curves)
    np.testing.assert_allclose(X[hole, 2], 10 * np.cos(np.deg2rad(18)), atol=1e-9)
    equator = select(Selector(nearest_curve=[20, 0, -1]), X, mask, curves)
    assert np.all(np.abs(X[equator, 2]) < 1e-9) and len(equator) == np.sum(np.abs(X[:, 2]) < 1e-9)
    quarter = select(Selector(nearest_curve=[0, 0, -5], expression="x >= 0 and y >= 0"),
                     X, mask, curves)
    assert 0 < len(quarter) < len(equator) / 3


def test_empty_selection_explains_the_boxes_and_the_fix(plate):
    X, mask, curves = plate
    with pytest.raises(InputError) as info:
        select(Selector(plane=[1, 0, 0, 6], name="clamped"), X, mask, curves)
    msg = str(info.value)
    assert "clamped" in msg and "plane" in msg and "[-5, -5, 0] to [5, 5, 0]" in msg
    assert "tol" in msg and "on_boundary" in msg and "boundary points span" in msg
    with pytest.raises(InputError, match="on_boundary"):  # interior point with on_boundary
        select(Selector(box=[-0.1, -0.1, -1, 0.1, 0.1, 1]), X, mask, curves)


def test_bad_selectors_raise_config_errors(plate):
    X, mask, curves = plate
    with pytest.raises(ConfigError, match="no criterion"):
        select(Selector(), X, mask, curves)
    with pytest.raises(ConfigError, match="plane"):
        select(Selector(plane=[1, 0, 0]), X, mask, curves)
    with pytest.raises(ConfigError, match="normal is zero"):
        select(Selector(plane=[0, 0, 0, 1]), X, mask, curves)
    with pytest.raises(ConfigError, match="box"):
        select(Selector(box=[0, 0, 0]), X, mask, curves)
    with pytest.raises(ConfigError, match="tol"):
        select(Selector(plane=[1, 0, 0, 5], tol=-1.0), X, mask, curves)


def test_tolerance_and_describe(plate):
    X, mask, curves = plate
    near = select(Selector(plane=[1, 0, 0, 4.9], tol=0.2), X, mask, curves)
    assert np.allclose(X[near, 0], 5.0)
    with pytest.raises(InputError):  # default tol = 0.25 h = 0.125 < 0.2: nothing on x = 4.8
        select(Selector(plane=[1, 0, 0, 4.8]), X, mask, curves)
    text = describe(Selector(plane=[1, 0, 0, 5], name="clamped"))
    assert text.startswith("clamped") and "plane=[1, 0, 0, 5]" in text and "on_boundary" in text


def test_selector_is_a_structured_config():
    omegaconf = pytest.importorskip("omegaconf")
    cfg = omegaconf.OmegaConf.structured(Selector)
    merged = omegaconf.OmegaConf.merge(cfg, omegaconf.OmegaConf.create(
        {"plane": [1, 0, 0, 5], "on_boundary": True}))
    sel = Selector(**omegaconf.OmegaConf.to_container(merged))
    assert sel.plane == [1.0, 0.0, 0.0, 5.0]
    assert {f.name for f in dataclasses.fields(Selector)} >= {
        "plane", "box", "expression", "nearest_curve", "on_boundary", "tol"}


def test_polyline_picks_the_points_within_tol_of_its_segments(plate):
    """Checked against the brute-force distance to a densely sampled copy of the polyline."""
    X, mask, curves = plate
    V = np.array([[-3.0, -1.0, 0.0], [0.5, 0.0, 0.0], [2.0, 3.5, 0.0]])
    got = select(Selector(polyline=V.tolist(), tol=0.3, on_boundary=False), X, mask, curves)
    t = np.linspace(0, 1, 20001)[:, None]
    dense = np.vstack([a + t * (b - a) for a, b in zip(V[:-1], V[1:])])
    from scipy.spatial import cKDTree

    d = cKDTree(dense).query(X)[0]
    want = np.flatnonzero(d <= 0.3)
    sure = np.flatnonzero(np.abs(d - 0.3) > 1e-3)     # away from the tolerance's edge
    np.testing.assert_array_equal(np.intersect1d(got, sure), np.intersect1d(want, sure))
    assert len(got) > 10


@pytest.mark.parametrize("polyline", [[[0, 0, 0]], [[0, 0], [1, 1]], "line", [[0, 0, np.nan],
                                                                             [1, 1, 1]]])
def test_a_malformed_polyline_is_a_config_error(plate, polyline):
    X, mask, curves = plate
    with pytest.raises(ConfigError, match="polyline=.*two or more points"):
        select(Selector(polyline=polyline, on_boundary=False), X, mask, curves)
