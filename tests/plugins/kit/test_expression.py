"""Selector expressions cannot change the points, and every bad one is one clear ConfigError."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pointatlas.errors import ConfigError
from pointatlas_kit.selectors import Selector, evaluate_expression, select


@pytest.fixture
def points():
    P = np.random.default_rng(3).normal(size=(12, 3))
    P[0] = 0.0  # the origin: theta, phi, 1/r and log(r) at their edge cases
    return P


def _refused(expression, P):
    """The ConfigError message for ``expression``; P must be left exactly as it was."""
    before = P.copy()
    with pytest.raises(ConfigError) as info:
        evaluate_expression(expression, P)
    np.testing.assert_array_equal(P, before)
    msg = str(info.value)
    assert "\n" not in msg and "Fix:" in msg
    return msg


@pytest.mark.parametrize("expression, takes", [
    ("sin(y, y) > -2", "sin takes 1 argument (x), got 2"),
    ("abs(x, z) >= 0", "abs takes 1 argument (x), got 2"),
    ("arctan2(y, x, y) < 9", "arctan2 takes 2 arguments (y, x), got 3"),
    ("minimum(x, y, z) < 9", "minimum takes 2 arguments (a, b), got 3"),
])
def test_an_output_array_passed_positionally_is_refused_and_writes_nothing(points, expression,
                                                                          takes):
    assert takes in _refused(expression, points)


def test_the_issue_s_attack_leaves_the_model_points_selectable(points):
    """sin(y, y) wrote sin(y) into the y coordinates, after which a plane on y found nothing."""
    points[:, 1] = np.arange(len(points)) - 2.0  # y = -2 ... 9: sin(y) ≠ y except at 0
    mask = np.ones(len(points), bool)
    with pytest.raises(ConfigError, match="sin takes 1 argument"):
        select(Selector(expression="sin(y, y) > -2"), points, mask, [])
    assert select(Selector(plane=[0, 1, 0, 7.0]), points, mask, []).tolist() == [9]


@pytest.mark.parametrize("expression, name", [
    ("abs(x, out=y) > 0", "abs"), ("isclose(x, 5, atol=1)", "isclose"),
    ("sin(**x) > 0", "sin"), ("arctan2(*x) > 0", "arctan2"), ("hypot(x, *y) > 0", "hypot"),
])
def test_keyword_and_starred_arguments_are_refused(points, expression, name):
    msg = _refused(expression, points)
    assert f"{name} takes" in msg and ("keyword" in msg or "starred" in msg)


def test_isclose_with_one_argument_is_one_line_with_the_fix(points):
    msg = _refused("isclose(x)", points)
    assert msg.startswith("selector expression 'isclose(x)': isclose takes 2 arguments (a, b), "
                          "got 1. Fix: write isclose(a, b)")
    assert "abs(a - b) < tol" in msg
    assert "sqrt takes 1 argument (x), got 0" in _refused("sqrt() < 1", points)
    np.testing.assert_array_equal(evaluate_expression("isclose(x, 0)", points),
                                  np.isclose(points[:, 0], 0))


@pytest.mark.parametrize("expression", [
    "x > 0 and " * 500 + "x > 0",          # 5005 characters
    "x" + " + x" * 3000 + " > 0",          # RecursionError in ast.parse before
    "-" * 5000 + "x > 0",
])
def test_a_very_long_expression_is_refused_before_parsing(points, expression):
    assert "characters long (at most" in _refused(expression, points)


@pytest.mark.parametrize("expression", [
    "(" * 200 + "x" + ")" * 200 + " > 0",
    "-" * 900 + "x > 0",
    "not " * 200 + "x > 0",
    "abs(" * 60 + "x" + ")" * 60 + " > 0",
    "x" + " ** x" * 100 + " > 0",
])
def test_deep_nesting_is_a_config_error_not_a_recursion_error(points, expression):
    assert "nested" in _refused(expression, points)


@pytest.mark.parametrize("expression, token", [
    ("~" + "-" * 990 + "x", "Invert"), ("(" + "-" * 900 + "x).real > 0", "Attribute"),
    ("isclose(" + "-" * 900 + "x)", "isclose takes 2 arguments"),
])
def test_a_refusal_above_a_deep_subtree_does_not_recurse_into_it(points, expression, token):
    assert token in _refused(expression, points)


def test_the_documented_limits_are_exact(points):
    from pointatlas_kit.expression import MAX_DEPTH, MAX_LENGTH

    ok = evaluate_expression("(" * MAX_DEPTH + "x" + ")" * MAX_DEPTH + " > 0", points)
    np.testing.assert_array_equal(ok, points[:, 0] > 0)
    _refused("(" * (MAX_DEPTH + 1) + "x" + ")" * (MAX_DEPTH + 1) + " > 0", points)
    # Compare > USub × k > Name: k + 2 levels
    signs = "-" * (MAX_DEPTH - 2)  # an even count: the same as x
    np.testing.assert_array_equal(evaluate_expression(signs + "x > 0", points), points[:, 0] > 0)
    _refused("-" + signs + "x > 0", points)
    text = "x" + " " * (MAX_LENGTH - 4) + "> 0"
    assert len(text) == MAX_LENGTH
    np.testing.assert_array_equal(evaluate_expression(text, points), points[:, 0] > 0)
    _refused("x " + text[1:], points)


@pytest.mark.parametrize("expression, problem", [
    ("1 < 2", "the single value True"), ("pi > 4", "the single value False"),
    ("-(x > 0)", "numpy cannot evaluate it"), ("1" * 400 + " < x", "not a finite float"),
    ("1e999 > x", "not a finite float"), ("sin > 0", "sin is a function"),
    ("x\0 > 0", "null bytes"), ("x > ", "not valid Python syntax"),
])
def test_results_and_numbers_that_are_not_one_truth_value_per_point(points, expression, problem):
    assert problem in _refused(expression, points)


def test_arithmetic_on_constants_follows_floating_point_rules(points):
    """pi / 0 is inf and e ** 1000 overflows to inf, as for the variables (no Python error)."""
    for expression in ("pi / (pi - pi) > x", "e ** 1000 > x", "-(e ** 1000) < x"):
        assert evaluate_expression(expression, points).all()
    assert not evaluate_expression("(pi - pi) / (e - e) == x", points).any()  # nan


_LEAVES = st.sampled_from(["x", "y", "z", "r", "rho", "theta", "phi", "pi", "e", "0", "2",
                           "0.5", "1e-6", "-3"])
_FUNCTIONS = st.sampled_from(["abs", "sqrt", "sin", "cos", "tan", "arcsin", "arccos", "arctan",
                              "arctan2", "exp", "log", "hypot", "minimum", "maximum",
                              "isclose"])
_OPERATORS = st.sampled_from(["+", "-", "*", "/", "**", "%", "<", "<=", ">", ">=", "==", "!=",
                              "and", "or"])


def _extend(children):
    return st.one_of(
        st.tuples(st.sampled_from(["-", "+", "not "]), children).map(lambda t: f"({t[0]}{t[1]})"),
        st.tuples(children, _OPERATORS, children).map(lambda t: f"({t[0]} {t[1]} {t[2]})"),
        st.tuples(_FUNCTIONS, st.lists(children, min_size=0, max_size=3)).map(
            lambda t: f"{t[0]}({', '.join(t[1])})"))


@settings(max_examples=300, deadline=None)
@given(st.recursive(_LEAVES, _extend, max_leaves=8), st.booleans())
def test_random_expressions_never_modify_the_points(expression, compare):
    P = np.random.default_rng(5).normal(size=(9, 3))
    P[0] = 0.0
    before = P.copy()
    text = f"{expression} > 0" if compare else expression
    try:
        value = evaluate_expression(text, P)
    except ConfigError as err:
        assert "\n" not in str(err) and "Fix:" in str(err)
    else:
        assert value.dtype == bool and value.shape == (len(P),)
    np.testing.assert_array_equal(P, before)
