"""The fused d = 2 LME kernel: exponentials, Taylor updates, agreement with the general one."""
import numpy as np
import pytest

from pointatlas_approximants import lme_kernels as K
from pointatlas_approximants.lme import LocalMaxEnt
from pointatlas_approximants.lme_kernel_2d import POLY_MAX, _scaled, lme_kernel_2d
from pointatlas_approximants.small_math import exp_shifted


def test_exp_shifted_matches_numpy_to_round_off():
    rng = np.random.default_rng(0)
    x = np.concatenate([-700.0 * rng.random(5000), [0.0, -1e-300, -0.3465735902799726,
                                                   -0.34657359027997264, -699.9, -700.0]])
    for shift in (0.0, 3.5):
        out = x + shift
        ib = np.empty(len(x), dtype=np.int64)
        exp_shifted(out, len(x), shift, ib)
        assert np.abs(out / np.exp(x) - 1.0).max() < 4e-15
    out = np.array([-701.0, -800.0, -np.inf])
    exp_shifted(out, 3, 0.0, np.empty(3, dtype=np.int64))
    assert (out >= 0.0).all() and (out < 1e-303).all()  # clamped, no overflow or NaN


@pytest.mark.parametrize("umax", [5e-5, 5e-3, 5e-2, POLY_MAX])
def test_taylor_update_matches_exponentials(umax):
    rng = np.random.default_rng(1)
    y0, y1 = rng.standard_normal(40), rng.standard_normal(40)
    d = np.array([0.6, -0.8]) * umax / np.hypot(y0, y1).max()  # max |d·y_a| <= umax
    p = rng.random(40) + 0.5
    q = np.empty(40)
    _scaled(p, q, y0, y1, 40, d[0], d[1], umax)
    u = d[0] * y0 + d[1] * y1
    assert np.abs(u).max() <= umax
    assert np.abs(q / (p * np.exp(u)) - 1.0).max() < 5e-16


@pytest.mark.parametrize("gamma", [0.5, 0.8, 3.0])
def test_2d_kernel_matches_general_kernel(ax, gamma):
    nodes = ax.nonuniform_nodes(2, 150, seed=4)
    model = LocalMaxEnt(gamma=gamma).fit(nodes)
    x = ax.inside_points(2, 40, seed=5)
    cells = model.grid_.cells(x)
    indptr = cells.count()
    nnz = int(indptr[-1])
    tol = model.newton_tol * model.h_ref_
    out = {}
    for name, kernel in [("2d", lme_kernel_2d), ("general", K.lme_kernel)]:
        arrays = [np.empty(nnz, dtype=np.int64), np.empty(nnz), np.empty((nnz, 2)),
                  np.empty((nnz, 2, 2)), np.empty(len(x), dtype=np.int64)]
        kernel(*cells.args(), model.entry_beta_, indptr, tol, 100, 2, *arrays)
        out[name] = arrays
    a, b = out["2d"], out["general"]
    np.testing.assert_array_equal(a[4], K.OK)
    np.testing.assert_array_equal(b[4], K.OK)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_allclose(a[1], b[1], rtol=0, atol=1e-13)
    for da, db in zip(a[2:4], b[2:4]):
        assert np.abs(da - db).max() < 1e-11 * np.abs(db).max()
    assert np.abs(a[3] - a[3].transpose(0, 2, 1)).max() == 0.0
