"""Line-search Newton with a preconditioned, truncated conjugate-gradient inner solve.

Used by NLIE (thesis Appendix C: "Newton's method with a line search"). The Hessian may be
singular (rigid motions of the embedding) and indefinite away from a minimum: CG stops at
negative curvature (Steihaug), and a small shift ``shift * mean(diag H)`` regularises the null
space.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np


@dataclass
class NewtonResult:
    x: np.ndarray
    fun: float
    grad_norm: float
    n_iter: int
    cg_iters: int
    converged: bool


def truncated_pcg(matvec: Callable, b: np.ndarray, precond: Callable, rtol: float,
                  max_iter: int) -> tuple[np.ndarray, int, bool]:
    """Approximately solve H x = b; stop at relative residual ``rtol`` or negative curvature.

    Returns (x, iterations, hit_negative_curvature)."""
    x = np.zeros_like(b)
    r = b.copy()
    z = precond(r)
    p = z.copy()
    rz = r @ z
    bnorm = np.linalg.norm(b)
    for it in range(1, max_iter + 1):
        Hp = matvec(p)
        curv = p @ Hp
        if curv <= 0:
            return (x if it > 1 else z), it, True
        a = rz / curv
        x += a * p
        r -= a * Hp
        if np.linalg.norm(r) <= rtol * bnorm:
            return x, it, False
        z = precond(r)
        rz_new = r @ z
        p = z + (rz_new / rz) * p
        rz = rz_new
    return x, max_iter, False


def newton_line_search(fun_grad: Callable, fun: Callable, hess: Callable, x0: np.ndarray, *,
                       grad_tol: float, max_iter: int = 50, max_cg: int = 500,
                       shift: float = 1e-10) -> NewtonResult:
    """Minimise ``fun`` from ``x0``.

    ``fun_grad(x) -> (f, g)``, ``fun(x) -> f``, ``hess(x) -> (matvec, precond, scale)`` where
    ``precond`` applies an approximation of H^{-1} and ``scale`` is a typical diagonal entry.
    Stops when max|g| <= ``grad_tol``. Where CG meets negative curvature early, the step is
    recomputed with H + mu scale I (Levenberg shift, mu raised x10, lowered after full steps).
    Armijo backtracking from the full step.
    """
    x = x0.copy()
    f, g = fun_grad(x)
    g0 = np.linalg.norm(g)
    cg_total = 0
    converged = bool(np.abs(g).max() <= grad_tol)
    it = 0
    mu = 0.0                                 # adaptive Levenberg shift (units of mean diag H)
    while not converged and it < max_iter:
        it += 1
        matvec, precond, scale = hess(x)
        gn = np.linalg.norm(g)
        eta = min(0.1, np.sqrt(gn / max(g0, 1e-300)))
        for _ in range(8):                   # raise the shift until CG sees positive curvature
            shift_abs = (mu + shift) * scale
            step, ncg, neg = truncated_pcg(lambda v: matvec(v) + shift_abs * v, -g, precond,
                                           eta, max_cg)
            cg_total += ncg
            if not neg or ncg > 5:
                break
            mu = max(10.0 * mu, 1e-3)
        slope = g @ step
        if slope >= 0:                      # not a descent direction: preconditioned gradient
            step = -precond(g)
            slope = g @ step
        alpha = 1.0
        while alpha > 1e-10:
            f_new = fun(x + alpha * step)
            if np.isfinite(f_new) and f_new <= f + 1e-4 * alpha * slope:
                break
            alpha *= 0.5
        else:
            break                            # no decrease: stationary to machine precision
        mu = mu * 0.1 if alpha == 1.0 else max(mu, 1e-4) * (1.0 if alpha > 0.2 else 10.0)
        if mu < 1e-8:
            mu = 0.0
        x = x + alpha * step
        f, g = fun_grad(x)
        converged = bool(np.abs(g).max() <= grad_tol)
    return NewtonResult(x, float(f), float(np.abs(g).max()), it, cg_total, converged)
