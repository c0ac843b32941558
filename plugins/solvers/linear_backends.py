"""Sparse symmetric linear solves behind one interface: factorise once, solve many times.

``factorize(A, backend)`` returns a :class:`Factorization` of the symmetric matrix A with
``solve(b)`` (A⁻¹b) and ``negative_pivots``, the number of negative eigenvalues of A by
Sylvester's law of inertia (the signs of D in A = LDLᵀ), or -1 when the backend cannot give
it. The path followers use that count to tell stable from unstable equilibria
(:mod:`.stability`).

===========  ==============================================================  ==========
backend      method                                                          inertia
===========  ==============================================================  ==========
``superlu``  SuperLU (scipy ``splu``): minimum degree on AᵀA + A, no          pivot signs
             pivoting (``diag_pivot_thresh=0``, symmetric mode); always
             available. The old name ``direct`` means this one.
``pardiso``  MKL PARDISO through ``pypardiso`` (extra ``fast``): symmetric    iparm(23)
             indefinite LDLᵀ (mtype −2, Bunch–Kaufman pivoting, upper
             triangle only), multi-threaded
``cg_amg``   conjugate gradients preconditioned by a smoothed-aggregation     none (-1)
             AMG V-cycle (``pyamg``, extra ``fast``); for SPD matrices
``cg_ilu``   conjugate gradients preconditioned by an incomplete LU          none (-1)
             (scipy ``spilu``); for SPD matrices
``auto``     ``pardiso`` if pypardiso is installed, else ``superlu``
===========  ==============================================================  ==========

With an iterative backend (-1) the stability check does not trust a missing count: it asks
Lanczos for negative eigenvalues and, when Lanczos sees none, the inertia of a direct
factorisation (:func:`.stability.confirmed_negative_count`), so stability stays right at the
cost of one direct factorisation per check.

A backend that is not installed is refused with a :class:`ConfigError` naming the extra.
"""
from __future__ import annotations

import functools
import os

import numpy as np
from scipy.sparse import csc_matrix, csr_matrix

from pointatlas.errors import ConfigError, InputError

from .symmetric_upper import symmetric_upper

#: The backends, in the order of the table above; ``auto`` and ``direct`` are names for two.
BACKENDS = ("superlu", "pardiso", "cg_amg", "cg_ilu")
CHOICES = (*BACKENDS, "auto", "direct")
#: Backends that give the inertia (negative_pivots ≥ 0).
WITH_INERTIA = ("superlu", "pardiso")
_NEEDS = {"pardiso": "pypardiso", "cg_amg": "pyamg"}

SINGULAR = ("the constrained stiffness matrix is singular: some motion (of the shell, the "
            "body) is not prevented by the supports, or the point cloud is too sparse for the "
            "chart support. Add supports or more points.")


def installed(backend: str) -> bool:
    """True if the package the backend needs can be imported."""
    module = _NEEDS.get(backend)
    if module is None:
        return True
    if module == "pypardiso":
        _reproducible_mkl()
    try:
        __import__(module)
    except (ImportError, OSError):   # OSError: pypardiso without a loadable MKL
        return False
    return True


def resolve_backend(name: str, key: str = "physics.solver") -> str:
    """The backend ``name`` stands for (``auto``, ``direct`` resolved); a :class:`ConfigError`
    naming ``key`` if it is unknown or not installed."""
    if name == "direct":
        return "superlu"
    if name == "auto":
        return "pardiso" if installed("pardiso") else "superlu"
    if name not in BACKENDS:
        raise ConfigError(f"{key} = {name!r} is unknown; use one of {CHOICES}.")
    if not installed(name):
        raise ConfigError(f"{key} = {name!r} needs {_NEEDS[name]}: pip install "
                          "'pointatlas[fast]'")
    return name


def inertia_backend(preferred: str) -> str:
    """``preferred`` if it gives the inertia, else the fastest installed one that does."""
    return preferred if preferred in WITH_INERTIA else resolve_backend("auto")


class Factorization:
    """A factorised (or preconditioned) symmetric matrix: ``solve(b)`` is A⁻¹b."""

    backend = ""
    negative_pivots = -1   # negative eigenvalues of A (inertia); -1: unknown

    def solve(self, b: np.ndarray) -> np.ndarray:
        raise NotImplementedError


def factorize(A, backend: str = "superlu", reuse: Factorization | None = None) -> Factorization:
    """A :class:`Factorization` of the symmetric sparse matrix A with ``backend`` (module
    doc); InputError if A is singular (direct backends), ConfigError if the backend is
    unknown or not installed. ``reuse``: a factorisation that will not be solved with again
    (a staggered or Newton iteration's previous matrix); PARDISO takes over its handle and,
    where the sparsity pattern is the same, skips the analysis (ordering and symbolic
    factorisation, ~half of a factorisation), the factors being those of a fresh one."""
    name = resolve_backend(backend)
    if name == "pardiso":
        return PardisoFactorization(A, reuse if isinstance(reuse, PardisoFactorization)
                                    else None)
    return {"superlu": SuperLUFactorization,
            "cg_amg": AMGConjugateGradient, "cg_ilu": ILUConjugateGradient}[name](A)


class SuperLUFactorization(Factorization):
    """SuperLU without pivoting in symmetric mode; the signs of U's diagonal are those of D
    in A = LDLᵀ (the inertia)."""

    backend = "superlu"

    def __init__(self, A):
        from scipy.sparse.linalg import splu

        A = csc_matrix(A)
        try:
            # K + ρCᵀC is symmetric positive definite: symmetric ordering, no pivoting
            # (2–3× faster than COLAMD with partial pivoting on shell stiffness matrices)
            self._lu = splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                            options={"SymmetricMode": True})
            diag = np.abs(self._lu.U.diagonal())
        except RuntimeError:  # SuperLU: "Factor is exactly singular"
            diag = np.zeros(1)
        if not np.all(np.isfinite(diag)) or diag.min() <= 1e-300:
            raise InputError(SINGULAR)
        # without pivoting, the signs of U's diagonal are those of D in A = LDLᵀ (inertia)
        self.negative_pivots = int((self._lu.U.diagonal() < 0).sum())

    def solve(self, b):
        return self._lu.solve(b)


class PardisoFactorization(Factorization):
    """MKL PARDISO, real symmetric indefinite (mtype −2) on the upper triangle of A; the
    inertia is iparm(22) (positive) and iparm(23) (negative eigenvalues). A pivot PARDISO
    had to perturb (iparm(14) > 0: A is singular or nearly so) makes every solve check its
    residual, and a solve that misses A x = b is refused as singular.

    The parameters are MKL's defaults for mtype −2 (METIS ordering, Bunch–Kaufman pivoting,
    no scaling or matching) except the pivot perturbation, 1e-13 instead of 1e-8
    (iparm(10) = 13, the nonsymmetric default): on the hemisphere's K + ρCᵀC (ρ ≈ 1e15
    relative to K, residual 1e-5 at best in double precision) the answer then differs from
    SuperLU's by 6e-8 on the sampled points' DOFs instead of 3e-7, and each solve skips two
    refinement steps (4× faster)."""

    backend = "pardiso"
    MTYPE = -2
    #: iparm (1-based) given to PARDISO; every other one is 0. iparm(34) = 2 with MKL's
    #: conditional numerical reproducibility (:func:`_reproducible_mkl`) makes the result
    #: the same from run to run: without it the 4 000-point hemisphere's displacement moved
    #: by 1e-4 relative between two identical runs (threaded reductions).
    IPARM = {1: 1, 2: 2, 8: 0, 10: 13, 11: 0, 13: 0, 21: 1, 34: 2}

    def __init__(self, A, reuse: "PardisoFactorization | None" = None):
        self.matrix = csr_matrix(A, dtype=float)
        n = self.matrix.shape[0]
        if n == 0 or self.matrix.shape[1] != n:
            raise InputError(f"pardiso needs a non-empty square matrix, got {A.shape}.")
        asym, self.upper = symmetric_upper(self.matrix)
        if asym > 1e-10 * max(abs(self.matrix.data).max(initial=0.0), 1e-300):
            raise InputError(f"pardiso (symmetric LDLᵀ) got a non-symmetric matrix "
                             f"(max |A − Aᵀ| = {asym:.3g}); use physics.solver=superlu.")
        same = reuse is not None and getattr(reuse, "_solver", None) is not None and \
            np.array_equal(reuse.upper.indptr, self.upper.indptr) and \
            np.array_equal(reuse.upper.indices, self.upper.indices)
        from pypardiso.pardiso_wrapper import PyPardisoError

        try:
            if same:   # the handle moves here: numerical factorisation only (phase 22)
                self._solver, reuse._solver = reuse._solver, None
                self._solver.remove_stored_factorization()
                self._solver.set_phase(22)
                self._solver._call_pardiso(self.upper, np.zeros((n, 1)))
                self._solver.factorized_A = self.upper.copy() if self.upper.nnz <= \
                    self._solver.size_limit_storage else \
                    self._solver._hash_csr_matrix(self.upper)
            else:
                self._solver = _pardiso_solver(self.MTYPE)
                self._solver.factorize(self.upper)
        except PyPardisoError as exc:
            raise InputError(f"{SINGULAR} (PARDISO: {exc})") from None
        self.perturbed_pivots = int(self._solver.get_iparm(14))
        self.negative_pivots = int(self._solver.get_iparm(23))

    def solve(self, b):
        if self._solver is None:
            from pointatlas.errors import PointatlasError

            raise PointatlasError("this PARDISO factorisation was handed on (factorize(..., "
                                  "reuse=)) and holds no factors any more.")
        b = np.asarray(b, dtype=float)
        x = self._solver.solve(self.upper, b)
        if self.perturbed_pivots:
            r = float(np.linalg.norm(self.matrix @ x - b))
            if not r <= 1e-8 * max(float(np.linalg.norm(b)), 1e-300):
                raise InputError(f"{SINGULAR} (PARDISO perturbed {self.perturbed_pivots} "
                                 f"pivot(s); relative residual {r / np.linalg.norm(b):.2e})")
        return x

    def __del__(self):
        solver = getattr(self, "_solver", None)
        if solver is not None:
            try:
                solver.free_memory(everything=True)   # MKL's memory of this handle
            except Exception:   # noqa: BLE001 (interpreter shutdown)
                pass


def _pardiso_solver(mtype: int):
    """A fresh pypardiso handle of matrix type ``mtype``. pypardiso looks for MKL by walking
    the whole environment on every new handle (0.7 s here) unless PYPARDISO_MKL_RT names the
    library: it is set to the one pypardiso found at import."""
    _reproducible_mkl()
    import pypardiso

    if not os.environ.get("PYPARDISO_MKL_RT"):
        os.environ["PYPARDISO_MKL_RT"] = pypardiso.ps.libmkl._name
    solver = pypardiso.PyPardisoSolver(mtype=mtype)
    solver.set_statistical_info_off()
    for i, value in PardisoFactorization.IPARM.items():
        solver.iparm[i - 1] = value
    return solver


def _reproducible_mkl() -> None:
    """Ask MKL for conditional numerical reproducibility (MKL_CBWR=AUTO,STRICT: the same
    code path and reduction order on every run on this CPU) unless the user set MKL_CBWR.
    MKL reads it when it loads, so this runs before pypardiso is first imported; an MKL
    loaded earlier by another library keeps its own setting. Also names MKL's runtime
    library for pypardiso (PYPARDISO_MKL_RT, unless set) from the ``mkl`` wheel's file list:
    without it, importing pypardiso walks the whole environment for it (0.7–1.5 s a process)."""
    os.environ.setdefault("MKL_CBWR", "AUTO,STRICT")
    if not os.environ.get("PYPARDISO_MKL_RT"):
        library = _mkl_runtime_library()
        if library:
            os.environ["PYPARDISO_MKL_RT"] = library


@functools.cache
def _mkl_runtime_library() -> str | None:
    """Path of libmkl_rt shipped by the installed ``mkl`` distribution, or None (looked up
    once a process)."""
    from importlib import metadata

    try:
        files = metadata.distribution("mkl").files or []
    except metadata.PackageNotFoundError:
        return None
    runtimes = (f for f in files if f.name.startswith(("libmkl_rt.", "mkl_rt.")))
    for name in sorted(runtimes, key=str):
        path = os.path.realpath(name.locate())
        if os.path.isfile(path):
            return path
    return None


class _ConjugateGradient(Factorization):
    """CG on a symmetric positive definite A with a preconditioner M ≈ A⁻¹ (no inertia)."""

    RTOL = 1e-12
    MAX_ITER = 2000

    def __init__(self, A, preconditioner):
        self.matrix = A
        self._M = preconditioner
        self.iterations = 0   # CG iterations of the last solve

    def solve(self, b):
        from scipy.sparse.linalg import cg

        count = [0]

        def tick(_):
            count[0] += 1

        x, info = cg(self.matrix, b, M=self._M, rtol=self.RTOL, maxiter=self.MAX_ITER,
                     callback=tick)
        self.iterations = count[0]
        if info != 0 or not np.all(np.isfinite(x)):
            raise InputError(f"CG preconditioned by {self.PRECONDITIONER} did not converge "
                             f"({info if info > 0 else 'breakdown'} iterations; CG needs a "
                             "positive definite matrix, which the tangent of an unstable "
                             "state is not): use physics.solver=superlu or pardiso.")
        return x


class ILUConjugateGradient(_ConjugateGradient):
    """CG with an incomplete LU of A (drop tolerance 1e-5, fill factor 20)."""

    backend = "cg_ilu"
    PRECONDITIONER = "incomplete LU"

    def __init__(self, A):
        from scipy.sparse.linalg import LinearOperator, spilu

        A = csc_matrix(A)
        ilu = spilu(A, drop_tol=1e-5, fill_factor=20)
        super().__init__(A, LinearOperator(A.shape, ilu.solve))


class AMGConjugateGradient(_ConjugateGradient):
    """CG with one smoothed-aggregation AMG V-cycle (pyamg, symmetric; near-null space the
    constant vector, pyamg's default) as preconditioner."""

    backend = "cg_amg"
    PRECONDITIONER = "smoothed-aggregation AMG"

    def __init__(self, A):
        import pyamg

        A = csr_matrix(A)
        # 'local' (Gershgorin) weighting of the prolongation smoother: the default estimates
        # a spectral radius from a random vector, so the same matrix would give other
        # iterates from run to run (and a resumed path other increments)
        self.hierarchy = pyamg.smoothed_aggregation_solver(
            A, symmetry="symmetric", smooth=("jacobi", {"omega": 4.0 / 3.0,
                                                        "weighting": "local"}))
        super().__init__(A, self.hierarchy.aspreconditioner(cycle="V"))

