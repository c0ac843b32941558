"""The stability check: negative eigenvalues of a factorised constrained tangent, confirmed
by Lanczos; a backend without inertia (-1) is never taken for stable."""
import numpy as np
import pytest
from scipy.sparse import csr_matrix

from pointatlas_solvers.augmented_lagrangian import ConstrainedSystem
from pointatlas_solvers.stability import confirmed_negative_count, negative_modes

from .test_branch_switching import Pitchfork


def test_a_negative_pivot_is_confirmed_by_the_eigenvalues():
    eq = Pitchfork()
    unstable = eq.system(np.array([1.2, 0.0, 0.0]))
    assert unstable.negative_pivots == 1 and confirmed_negative_count(unstable) == 1
    stable = eq.system(np.array([0.5, 0.0, 0.0]))
    assert confirmed_negative_count(stable) == 0
    # a pivot sign flipped by round-off (forced here) is not taken for an instability
    stable.negative_pivots = 1
    assert confirmed_negative_count(stable) == 0


def test_a_negative_eigenvalue_is_found_beyond_a_cluster_of_weak_ghost_modes():
    import scipy.sparse as sp

    d = np.r_[1e-6 + 1e-8 * np.arange(50), -0.01, np.linspace(1.0, 100.0, 400)]
    system = ConstrainedSystem(sp.diags(d).tocsr(), csr_matrix((1, d.size)))
    vals, vecs = negative_modes(system, system.negative_pivots)
    assert vals.tolist() == pytest.approx([-0.01]) and abs(vecs[50, 0]) == pytest.approx(1.0)


def test_a_negative_eigenvalue_that_lanczos_misses_is_confirmed_by_a_shifted_inertia(
        monkeypatch):
    """Behind a dense cluster of tiny positive ghost modes Lanczos may not converge to the
    negative eigenvalue (seen on the pull-out cylinder); the inertia of K_ρ + τI decides."""
    import scipy.sparse as sp

    import pointatlas_solvers.stability as bs

    d = np.r_[2e-5 + 1e-8 * np.arange(300), -0.6, np.linspace(1.0, 1e6, 300)]
    system = ConstrainedSystem(sp.diags(d).tocsr(), csr_matrix((1, d.size)))
    assert system.negative_pivots == 1
    # Lanczos returns no negative value, only the nearest-zero ghost modes it saw first
    monkeypatch.setattr(bs, "negative_modes",
                        lambda *a, **k: (np.zeros(0), np.zeros((d.size, 0)), d[:7]))
    assert bs.confirmed_negative_count(system) == 1      # real: kept
    # the same Lanczos miss on a stable matrix whose pivot sign flipped: not an instability
    stable = ConstrainedSystem(sp.diags(np.abs(d)).tocsr(), csr_matrix((1, d.size)))
    stable.negative_pivots = 1
    assert bs.confirmed_negative_count(stable) == 0


@pytest.mark.parametrize("backend", ["cg_ilu", "cg_amg"])
def test_a_backend_without_inertia_is_checked_by_lanczos_and_a_direct_inertia(backend):
    """-1 (no inertia) is never read as stable or unstable: Lanczos counts the negative
    eigenvalues it finds, and when it finds none a direct factorisation decides."""
    if backend == "cg_amg":
        pytest.importorskip("pyamg")
    eq = Pitchfork(backend)
    unstable = eq.system(np.array([1.2, 0.0, 0.0]))   # K_yy = 1 − x = −0.2
    assert unstable.negative_pivots == -1 and confirmed_negative_count(unstable) == 1
    stable = eq.system(np.array([0.5, 0.0, 0.0]))
    assert stable.negative_pivots == -1 and confirmed_negative_count(stable) == 0


def test_an_unknown_count_falls_back_on_a_direct_inertia_when_lanczos_sees_nothing(
        monkeypatch):
    import scipy.sparse as sp

    import pointatlas_solvers.stability as bs

    d = np.r_[2e-5 + 1e-8 * np.arange(300), -0.6, np.linspace(1.0, 1e6, 300)]
    system = ConstrainedSystem(sp.diags(d).tocsr(), csr_matrix((1, d.size)))
    system.negative_pivots = -1        # as an iterative backend reports it
    monkeypatch.setattr(bs, "negative_modes",
                        lambda *a, **k: (np.zeros(0), np.zeros((d.size, 0)), d[:7]))
    assert bs.confirmed_negative_count(system) == 1
    stable = ConstrainedSystem(sp.diags(np.abs(d)).tocsr(), csr_matrix((1, d.size)))
    stable.negative_pivots = -1
    assert bs.confirmed_negative_count(stable) == 0
    # and when ARPACK fails outright, the direct inertia (unshifted) still decides

    def broken(*a, **k):
        raise RuntimeError("ARPACK error -9999")

    monkeypatch.setattr(bs, "negative_modes", broken)
    assert bs.confirmed_negative_count(system) == 1
    assert bs.confirmed_negative_count(stable) == 0


def test_a_path_on_an_iterative_backend_reports_stability_like_a_direct_one():
    from pointatlas_solvers.path_following import follow_path
    from pointatlas_solvers.increment import PathSettings

    path = PathSettings(n_increments=5, max_load_factor=1.5, tol=1e-10, max_newton=20)
    direct = follow_path(Pitchfork("superlu"), path)
    iterative = follow_path(Pitchfork("cg_ilu"), path)
    assert [i.stable for i in iterative] == [i.stable for i in direct] == [
        i.load_factor < 1.0 for i in direct]
    assert [i.negative_pivots for i in iterative] == [i.negative_pivots for i in direct]
