"""Shape descriptors: B-spline refit, area, volume and reduced volume against closed forms."""
import numpy as np
import pytest

from pointatlas_studies.metaboly_shapes import area_volume, descriptors, fit_curve, reduced_volume


def spheroid(a, c, n=300):
    th = np.linspace(0, np.pi, n)
    return np.column_stack([a * np.sin(th), c * np.cos(th)])


def test_refit_keeps_a_circle_and_resamples_by_arclength():
    f = fit_curve(spheroid(1.0, 1.0), n_intervals=24, n_points=101)
    assert np.abs(np.hypot(*f.T) - 1).max() < 1e-5
    seg = np.linalg.norm(np.diff(f, axis=0), axis=1)
    assert np.ptp(seg) < 1e-3 * seg.mean()
    assert f[0, 0] == 0 and f[-1, 0] == 0 and f[0, 1] > f[-1, 1]


@pytest.mark.parametrize("a, c", [(1.0, 1.0), (1.0, 3.0), (2.0, 0.7)])
def test_area_and_volume_of_spheroids(a, c):
    """Closed forms: V = 4π a² c / 3; S of a prolate / oblate spheroid."""
    S, V = area_volume(fit_curve(spheroid(a, c), n_points=401))
    assert V == pytest.approx(4 * np.pi * a * a * c / 3, rel=2e-4)
    if c > a:
        e = np.sqrt(1 - a * a / (c * c))
        S_ref = 2 * np.pi * a * a * (1 + c / (a * e) * np.arcsin(e))
    elif c < a:
        e = np.sqrt(1 - c * c / (a * a))
        S_ref = 2 * np.pi * a * a * (1 + (1 - e * e) / e * np.arctanh(e))
    else:
        S_ref = 4 * np.pi * a * a
    assert S == pytest.approx(S_ref, rel=2e-4)
    assert reduced_volume(4 * np.pi, 4 * np.pi / 3) == pytest.approx(1.0)


def test_descriptors_of_a_sequence():
    d = descriptors([spheroid(1.0, 1.0 + 0.1 * k) for k in range(5)], n_points=51)
    assert d["vectors"].shape == (5, 102)
    assert (np.diff(d["reduced_volume"]) < 0).all()       # more elongated, less round
    assert d["area_deviation"] > 0.1
