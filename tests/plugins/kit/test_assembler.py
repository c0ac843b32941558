"""The kit's one assembler: FD consistency for one and several fields, refusals."""
import numpy as np
import pytest

from pointatlas.errors import ConfigError
from pointatlas.physics_conformance import check_discrete_energy, curved_patch
from pointatlas_kit.assembler import Assembler
from pointatlas_kit.energy import DiscreteEnergy, LinearSource
from pointatlas_kit.fields import Field, FieldLayout

PHI = Field("phase", components=1, order=1)
DISP = Field("displacement", components=3, order=2, value=False)


class Coupled:
    """W = (½ + φ²) |δy|² + φ_,1 φ_,2: a made-up energy of two fields (jet: φ, φ_,1, φ_,2,
    then the 15 displacement derivatives), nonlinear and coupling both."""

    fields = (PHI, DISP)
    density_names = ("coupled",)
    frame_invariant = False

    def point_data(self, q):
        return np.zeros((q.n_points, 1))

    def evaluate(self, jets, data, want):
        p, p1, p2, y = jets[:, 0], jets[:, 1], jets[:, 2], jets[:, 3:]
        s = (y * y).sum(axis=1)
        a = 0.5 + p * p
        dens = (a * s + p1 * p2)[:, None]
        g = H = None
        if want >= 1:
            g = np.zeros_like(jets)
            g[:, 0], g[:, 1], g[:, 2] = 2 * p * s, p2, p1
            g[:, 3:] = 2 * a[:, None] * y
        if want >= 2:
            n = jets.shape[1]
            H = np.zeros((len(jets), n, n))
            H[:, 0, 0] = 2 * s
            H[:, 1, 2] = H[:, 2, 1] = 1.0
            H[:, 0, 3:] = H[:, 3:, 0] = 4 * p[:, None] * y
            H[:, 3:, 3:] = 2 * a[:, None, None] * np.eye(n - 3)
        return dens, g, H


class Physics:
    """Just enough of a physics for the conformance check."""

    def __init__(self, fields, energies):
        self.fields, self._energies = fields, energies

    def discrete_energy(self, patch):
        return DiscreteEnergy(self.fields, self._energies, patch)


def test_two_fields_pass_the_conformance_check():
    check_discrete_energy(Physics((PHI, DISP), [Coupled()]))


def test_dof_numbering_is_node_major():
    L = FieldLayout((PHI, DISP), n_nodes=5)
    assert L.block == 4 and L.n_dofs == 20
    assert L.dofs("phase", [0, 2]).ravel().tolist() == [0, 8]
    assert L.dofs("displacement", [1], [2]).ravel().tolist() == [4 + 1 + 2]
    assert L.jet_size == 3 + 15


def test_a_wrong_tangent_is_caught_and_named():
    class WrongTangent(Coupled):
        def evaluate(self, jets, data, want):
            d, g, H = super().evaluate(jets, data, want)
            if H is not None:
                H = 1.01 * H
            return d, g, H

    with pytest.raises(AssertionError, match=r"tangent disagrees .* worst entry K\["):
        check_discrete_energy(Physics((PHI, DISP), [WrongTangent()]))


def test_a_wrong_residual_is_caught():
    class WrongGradient(Coupled):
        def evaluate(self, jets, data, want):
            d, g, H = super().evaluate(jets, data, want)
            if g is not None:
                g = g.copy()
                g[:, 0] *= 2.0
            return d, g, H

    with pytest.raises(AssertionError, match="residual disagrees"):
        check_discrete_energy(Physics((PHI, DISP), [WrongGradient()]))


def test_refusals_name_the_fix():
    patch = curved_patch(n=4)
    with pytest.raises(ConfigError, match=r"declared but no energy uses them"):
        DiscreteEnergy((PHI, DISP), [LinearSource(PHI, np.zeros(len(patch["weights"])))], patch)
    with pytest.raises(ConfigError, match="does not declare"):
        DiscreteEnergy((PHI,), [Coupled()], patch)
    with pytest.raises(ConfigError, match="components 0..0"):
        FieldLayout((PHI,), 3).dofs("phase", [0], [1])
    with pytest.raises(ConfigError, match="order"):
        Field("bad", components=1, order=3)


def test_linear_source_is_external_work():
    """R(0) = −∫ s p_a dΓ: the load vector of a source s = 1 sums to minus the area."""
    patch = curved_patch(n=5)
    de = DiscreteEnergy((PHI,), [LinearSource(PHI, np.ones(len(patch["weights"])))], patch)
    _, R = de.residual(np.zeros(de.n_dofs))
    assert np.isclose(R.sum(), -patch["weights"].sum(), rtol=1e-10)
    assert Assembler  # the public entry point


class ManyThreadsInProcess:
    """A 'distributed' executor of ``threads`` threads that runs the tasks here (pickled and
    unpickled, as a cluster would receive them)."""

    distributed = True

    def __init__(self, threads):
        self.threads, self.calls = threads, []

    def n_threads(self):
        return self.threads

    def map(self, fn, items, *, shared=None, shared_key=None, desc="", labels=None, costs=None):
        import pickle

        shared = pickle.loads(pickle.dumps(shared))
        self.calls.append((desc, len(items)))
        return [fn(shared, item) for item in items]

    def close(self):
        pass


@pytest.mark.parametrize("threads", [1, 7])
def test_parts_on_a_cluster_sum_to_the_local_tangent_and_residual(threads):
    """The tangent and residual cut into a cluster's parts (7 threads: each local range in
    pieces) are the local ones: bit for bit with as many parts, to round-off with more."""
    from pointatlas.executor import using_executor

    de = DiscreteEnergy((PHI, DISP), [Coupled()], curved_patch(24))
    U = np.random.default_rng(2).normal(scale=0.1, size=de.n_dofs)
    K0, (W0, R0) = de.assembler.tangent(U), de.assembler.residual(U)
    ex = ManyThreadsInProcess(threads)
    with using_executor(ex):
        K1, (W1, R1) = de.assembler.tangent(U), de.assembler.residual(U)
    assert [d for d, _ in ex.calls] == ["tangent assembly", "residual assembly"]
    if threads > 1:
        assert all(n > 2 for _, n in ex.calls), ex.calls
    scale = abs(K0).max()
    assert abs(K1 - K0).max() <= 1e-14 * scale
    assert np.max(np.abs(R1 - R0)) <= 1e-14 * np.max(np.abs(R0)) and W1 == pytest.approx(W0, rel=1e-14)


class SendsSharedOnce(ManyThreadsInProcess):
    """A distributed executor's caching, in process: the shared object is sent (pickled) once
    per ``shared_key`` and reused while the key is the same, as the Dask executor does."""

    def __init__(self, threads):
        super().__init__(threads)
        self.sent = {}

    def map(self, fn, items, *, shared=None, shared_key=None, desc="", labels=None, costs=None):
        import pickle

        if shared_key is None or shared_key not in self.sent:
            self.sent = {shared_key: pickle.loads(pickle.dumps(shared))}
        self.calls.append((desc, len(items)))
        return [fn(self.sent[shared_key], item) for item in items]


def test_a_freed_assemblers_key_is_not_reused_by_the_next(monkeypatch):
    """Two short-lived assemblers in turn (two loads' residuals) on a distributed executor,
    the second created where the first was freed: its residual is its own. The key was
    ``id(self)``: CPython reuses a freed object's address, the second load was assembled with
    the first's cached copy (the linear hemisphere on dask came out 11 % off, once in CI).
    Here every ``id()`` in the assembler's module is made equal, the worst case of reuse."""
    import pointatlas_kit.assembler as assembler_module
    from pointatlas.executor import using_executor

    monkeypatch.setattr(assembler_module, "id", lambda obj: 0, raising=False)
    patch = curved_patch(n=5)
    m = len(patch["weights"])
    residuals = {}
    ex = SendsSharedOnce(2)
    for scale in (1.0, 3.0):
        de = DiscreteEnergy((PHI,), [LinearSource(PHI, scale * np.ones(m))], patch)
        U = np.zeros(de.n_dofs)
        local = de.assembler.residual(U)[1]
        with using_executor(ex):
            residuals[scale] = (de.assembler.residual(U)[1], local)
        del de
    for scale, (on_cluster, local) in residuals.items():
        np.testing.assert_array_equal(on_cluster, local)
    np.testing.assert_allclose(residuals[3.0][0], 3.0 * residuals[1.0][0], rtol=1e-14)


class FixedQuadratic:
    """W = ½ jᵀ A j on the displacement's 15 derivatives, A a fixed random symmetric matrix
    (one field: the batched BLAS path of the tangent)."""

    fields = (DISP,)
    density_names = ("quadratic",)
    frame_invariant = False
    A = (lambda M: M + M.T)(np.random.default_rng(5).normal(size=(15, 15)))

    def point_data(self, q):
        return np.zeros((q.n_points, 1))

    def evaluate(self, jets, data, want):
        Aj = jets @ self.A
        dens = 0.5 * (jets * Aj).sum(axis=1)[:, None]
        H = np.broadcast_to(self.A, (len(jets), 15, 15)).copy() if want >= 2 else None
        return dens, (Aj if want >= 1 else None), H


def test_the_tangents_threads_keep_blas_at_one_thread_until_the_last_is_done(monkeypatch):
    """BLAS is limited to one thread around the tangent's threads, once, by the thread that
    starts them: a part still running after another has finished has BLAS at one thread,
    and BLAS has its thread count back afterwards. (With the limit set and restored inside
    each part, the first part's exit gave the second multithreaded BLAS mid-way, which
    changed the tangent at round-off from call to call, and left BLAS at one thread.)"""
    import threading

    import numba
    from threadpoolctl import threadpool_info, threadpool_limits

    import pointatlas_kit.assembler as asm

    def blas_threads():  # the OpenBLAS of numpy and scipy, which the tangent's np.dot calls
        # (MKL, loaded for PARDISO, keeps its limit per thread and is not used by the tangent)
        return sorted({i["num_threads"] for i in threadpool_info()
                       if i["user_api"] == "blas" and i["internal_api"] == "openblas"})

    de = DiscreteEnergy((DISP,), [FixedQuadratic()], curved_patch(24))
    if numba.get_num_threads() < 2 or len(de.assembler.q.assembly_plan().thread_bounds) < 2:
        pytest.skip("needs two assembly threads")
    first_done, seen, local = threading.Event(), [], threading.local()
    tangent_range, tangent_blocks = asm.Assembler.tangent_range, asm.tangent_blocks

    def timed_range(self, U, b0, b1):
        local.first, local.recorded = b0 == 0, False
        out = tangent_range(self, U, b0, b1)
        if b0 == 0:
            first_done.set()
        return out

    def watched_blocks(*args):
        if not local.first and not local.recorded:   # the second part waits for the first
            first_done.wait(60)
            seen.append(blas_threads())
            local.recorded = True
        return tangent_blocks(*args)

    monkeypatch.setattr(asm.Assembler, "tangent_range", timed_range)
    monkeypatch.setattr(asm, "tangent_blocks", watched_blocks)
    with threadpool_limits(limits=2, user_api="blas"):
        K = de.assembler.tangent(np.zeros(de.n_dofs))
        assert blas_threads() == [2]
    assert seen == [[1]] and abs(K).max() > 0
