"""Line-search Newton-CG: convergence where the objective's round-off hides the decrease."""
import numpy as np
import pytest

from pointatlas_embedders.newton_cg import approximate_wolfe_step, newton_line_search


def noisy_quadratic(n, noise, seed=0):
    """f = 1 + ½ (x - x*)ᵀ A (x - x*) + noise · sin(1e7 Σx) (A SPD, cond 100), the gradient
    that of the quadratic: as a sum over millions of terms, f carries a round-off that does
    not follow the decrease, while the gradient stays exact to round-off."""
    rng = np.random.default_rng(seed)
    Q = np.linalg.qr(rng.standard_normal((n, n)))[0]
    A = Q @ np.diag(np.geomspace(1, 100, n)) @ Q.T
    xs = rng.standard_normal(n)

    def fun_grad(x):
        r = x - xs
        return 1.0 + 0.5 * r @ A @ r + noise * np.sin(1e7 * x.sum()), A @ r

    def hess(x, convex):
        return (lambda v: 0.8 * (A @ v)), (lambda v: v)   # 20 % off: steps of 1.25 Newton

    return fun_grad, (lambda x: fun_grad(x)[0]), hess, xs


@pytest.mark.parametrize("noise", [0.0, 1e-10])
def test_newton_reaches_a_gradient_below_what_f_can_resolve(noise):
    """With noise 1e-10, Armijo cannot see decreases below it (|g| ~ 1e-5): the approximate
    Wolfe steps take the gradient to 1e-10."""
    fun_grad, fun, hess, xs = noisy_quadratic(20, noise)
    tol = 1e-10
    out = newton_line_search(fun_grad, fun, hess, np.zeros(20), max_iter=100,
                             converged=lambda g: np.abs(g).max() <= tol)
    assert out.converged and np.abs(out.grad).max() <= tol
    np.testing.assert_allclose(out.x, xs, atol=1e-10)


def test_the_approximate_wolfe_step_refuses_an_ascent():
    fun_grad, _, _, xs = noisy_quadratic(5, 1e-10)
    x = xs + 1e-7
    f, g = fun_grad(x)
    assert approximate_wolfe_step(fun_grad, x, f, float(g @ g), g) is None   # uphill
    found = approximate_wolfe_step(fun_grad, x, f, float(-g @ g), -0.01 * g)
    assert found is not None and np.abs(found[2]).max() < np.abs(g).max()
