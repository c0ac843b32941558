"""Every linear-solver backend against scipy's own spsolve (UMFPACK/SuperLU with partial
pivoting), the inertia against numpy's eigenvalues, and the refusals (not installed,
singular, not symmetric, CG on an indefinite matrix)."""
import sys

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from pointatlas.errors import ConfigError, InputError
from pointatlas_solvers.linear_backends import (BACKENDS, factorize, inertia_backend,
                                                installed, resolve_backend)


def laplacian(n: int = 12) -> sp.csr_matrix:
    """The 5-point Laplacian on an n × n grid (SPD, eigenvalues 4 sin²… known in closed form)."""
    L1 = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    return sp.kronsum(L1, L1).tocsr()


def shifted_laplacian(n: int = 12, below: int = 11):
    """(A − σI, count): σ between the ``below``-th and next eigenvalue, from the closed form
    λ_jk = 4 sin²(jπ/2(n+1)) + 4 sin²(kπ/2(n+1)); indefinite with ``below`` negative ones."""
    s = 4 * np.sin(np.arange(1, n + 1) * np.pi / (2 * (n + 1))) ** 2
    lam = np.sort((s[:, None] + s[None, :]).ravel())
    sigma = 0.5 * (lam[below - 1] + lam[below])
    return (laplacian(n) - sigma * sp.identity(n * n)).tocsr(), below


def available(backend):
    if not installed(backend):
        pytest.skip(f"{backend} is not installed (pip install 'pointatlas[fast]')")
    return backend


RHS = np.random.default_rng(0).normal(size=144)


@pytest.mark.parametrize("backend", BACKENDS)
def test_each_backend_solves_a_positive_definite_system(backend):
    A = laplacian()
    f = factorize(A, available(backend))
    ref = spsolve(A.tocsc(), RHS)
    np.testing.assert_allclose(f.solve(RHS), ref, rtol=0, atol=1e-10 * np.abs(ref).max())
    assert f.backend == backend
    assert f.negative_pivots == (0 if backend in ("superlu", "pardiso") else -1)


@pytest.mark.parametrize("backend", ["superlu", "pardiso", "cg_ilu"])
def test_each_backend_solves_an_indefinite_symmetric_system(backend):
    A, _ = shifted_laplacian()
    ref = spsolve(A.tocsc(), RHS)
    x = factorize(A, available(backend)).solve(RHS)
    np.testing.assert_allclose(x, ref, rtol=0, atol=1e-10 * np.abs(ref).max())


def test_cg_amg_refuses_an_indefinite_system_naming_the_direct_backends():
    """CG needs a positive definite matrix; with a V-cycle of an indefinite one it does not
    converge and says what to use instead (cg_ilu above only converges because its
    incomplete LU of so small a matrix is nearly exact)."""
    A, _ = shifted_laplacian()
    with pytest.raises(InputError, match="positive definite.*superlu or pardiso"):
        factorize(A, available("cg_amg")).solve(RHS)


@pytest.mark.parametrize("backend", ["superlu", "pardiso"])
def test_inertia_equals_the_count_of_negative_eigenvalues(backend):
    available(backend)
    A, count = shifted_laplacian()
    assert factorize(A, backend).negative_pivots == count
    rng = np.random.default_rng(3)
    for _ in range(3):   # small random sparse symmetric matrices of mixed inertia
        M = rng.normal(size=(40, 40)) * (rng.uniform(size=(40, 40)) < 0.15)
        M = M + M.T + np.diag(rng.normal(size=40) * 3)
        want = int((np.linalg.eigvalsh(M) < 0).sum())
        assert 5 < want < 35
        assert factorize(sp.csr_matrix(M), backend).negative_pivots == want


def test_pardiso_takes_a_saddle_point_matrix_with_zero_diagonal():
    """[[K, Cᵀ], [C, 0]]: PARDISO's symmetric format needs the (zero) diagonal stored; the
    inertia is n positive and r negative (K positive definite, C of full rank)."""
    available("pardiso")
    rng = np.random.default_rng(1)
    K, C = laplacian(5), sp.csr_matrix(rng.normal(size=(4, 25)))
    A = sp.bmat([[K, C.T], [C, None]]).tocsr()
    b = rng.normal(size=29)
    f = factorize(A, "pardiso")
    np.testing.assert_allclose(f.solve(b), spsolve(A.tocsc(), b), rtol=1e-10, atol=1e-12)
    assert f.negative_pivots == 4


def test_pardiso_reuses_the_analysis_of_a_matrix_of_the_same_pattern():
    """A factorisation handed on (reuse=) gives its handle to the new one: with the same
    pattern only the numerical phase runs, and the answers are a fresh factorisation's to
    the last bit; the old one then refuses to solve, and another pattern gets a fresh
    analysis."""
    from pointatlas.errors import PointatlasError

    available("pardiso")
    A = laplacian(14) + sp.identity(14 * 14, format="csr")
    scaled = sp.diags(np.linspace(1.0, 3.0, A.shape[0]))
    B = (scaled @ A @ scaled).tocsr()         # same pattern, other values, still SPD
    b = np.random.default_rng(0).standard_normal(A.shape[0])
    first = factorize(A, "pardiso")
    x_a = first.solve(b)
    second = factorize(B, "pardiso", reuse=first)
    assert second._solver is not None and first._solver is None
    np.testing.assert_array_equal(second.solve(b), factorize(B, "pardiso").solve(b))
    np.testing.assert_allclose(B @ second.solve(b), b, rtol=0, atol=1e-10)
    with pytest.raises(PointatlasError, match="handed on"):
        first.solve(b)
    other = laplacian(10) + sp.identity(100, format="csr")
    third = factorize(other, "pardiso", reuse=second)
    np.testing.assert_allclose(other @ third.solve(b[:100]), b[:100], atol=1e-10)
    np.testing.assert_allclose(x_a, spsolve(A.tocsc(), b), atol=1e-10)


@pytest.mark.parametrize("backend", ["superlu", "pardiso"])
def test_a_singular_matrix_is_refused(backend):
    A = sp.diags([1.0, 1.0, 0.0]).tocsr()
    with pytest.raises(InputError, match="singular"):
        factorize(A, available(backend)).solve(np.ones(3))


def test_pardiso_refuses_a_non_symmetric_matrix():
    A = sp.csr_matrix(np.array([[2.0, 1.0], [0.0, 2.0]]))
    with pytest.raises(InputError, match="non-symmetric.*superlu"):
        factorize(A, available("pardiso"))


@pytest.mark.parametrize("backend,module", [("pardiso", "pypardiso"), ("cg_amg", "pyamg")])
def test_a_backend_that_is_not_installed_names_the_extra(monkeypatch, backend, module):
    monkeypatch.setitem(sys.modules, module, None)     # import now raises ImportError
    assert not installed(backend)
    with pytest.raises(ConfigError) as err:
        factorize(laplacian(3), backend)
    assert str(err.value) == (f"physics.solver = {backend!r} needs {module}: pip install "
                              "'pointatlas[fast]'")
    if backend == "pardiso":   # auto falls back on SuperLU, which gives the inertia too
        assert resolve_backend("auto") == "superlu" == inertia_backend("cg_amg")


def test_names_resolve_and_an_unknown_one_lists_the_choices():
    assert resolve_backend("direct") == "superlu"
    assert resolve_backend("auto") == ("pardiso" if installed("pardiso") else "superlu")
    assert inertia_backend("superlu") == "superlu"
    assert inertia_backend("cg_ilu") == resolve_backend("auto")
    with pytest.raises(ConfigError, match="physics.solver = 'umfpack' is unknown.*superlu"):
        resolve_backend("umfpack")


_SOLVE_TWICE = r"""
import hashlib, os, sys
import numpy as np
import scipy.sparse as sp
from pointatlas_solvers.linear_backends import factorize, installed
assert installed("pardiso")
n = 60
L = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
I = sp.eye(n)
A = (sp.kron(sp.kron(L, I), I) + sp.kron(sp.kron(I, L), I) + sp.kron(sp.kron(I, I), L)).tocsr()
A = A + sp.diags(np.random.default_rng(0).uniform(0, 1e-3, n ** 3))
x = factorize(A, "pardiso").solve(np.random.default_rng(1).standard_normal(n ** 3))
print(os.environ.get("MKL_CBWR"), hashlib.sha256(x.tobytes()).hexdigest())
"""


@pytest.mark.skipif(not installed("pardiso"), reason="needs pypardiso (extra fast)")
def test_pardiso_gives_the_same_bits_in_two_processes():
    """MKL's conditional numerical reproducibility is switched on before MKL loads
    (MKL_CBWR=AUTO,STRICT, iparm(34)): two fresh processes solving the same 216 000-DOF
    system agree bit for bit (without it, two identical 4 000-point hemisphere runs
    differed by 1e-4 relative)."""
    import os
    import subprocess
    import sys

    env = {k: v for k, v in os.environ.items() if k != "MKL_CBWR"}
    out = [subprocess.run([sys.executable, "-c", _SOLVE_TWICE], capture_output=True, text=True,
                          env=env, timeout=300) for _ in range(2)]
    assert all(o.returncode == 0 for o in out), out[0].stderr[-2000:]
    lines = [o.stdout.split() for o in out]
    assert lines[0][0] == "AUTO,STRICT"
    assert lines[0][1] == lines[1][1]


_IMPORT_WITHOUT_A_WALK = r"""
import glob
def walk(*args, **kwargs):
    raise AssertionError("pypardiso walked the environment for MKL")
glob.glob = walk
import os
from pointatlas_solvers.linear_backends import installed
assert installed("pardiso")
import pypardiso
print(os.environ["PYPARDISO_MKL_RT"], pypardiso.ps.libmkl._name)
"""


@pytest.mark.skipif(not installed("pardiso"), reason="needs pypardiso (extra fast)")
def test_pardiso_loads_the_mkl_of_the_mkl_wheel_without_walking_the_environment():
    """PYPARDISO_MKL_RT is set from the ``mkl`` distribution's file list before pypardiso is
    imported: pypardiso loads that library and does not glob the environment for one."""
    import os
    import subprocess

    env = {k: v for k, v in os.environ.items() if k != "PYPARDISO_MKL_RT"}
    out = subprocess.run([sys.executable, "-c", _IMPORT_WITHOUT_A_WALK], capture_output=True,
                         text=True, env=env, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    named, loaded = out.stdout.split()
    assert named == loaded and os.path.isfile(loaded) and "mkl_rt" in os.path.basename(loaded)
