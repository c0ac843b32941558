"""The streamed tangent (chart groups rebuild their basis, assemble, drop it) is the kit's
tangent: on an ellipsoid made here, linear and at a deformed state, on this process and on a
Dask LocalCluster; its block sum is scipy's; a wrong call is one clear line."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.sparse import bsr_matrix

from pointatlas.errors import InputError
from pointatlas.executor import using_executor
from pointatlas.pointcloud import PointCloud
from pointatlas_atlas.atlas import Atlas, AtlasSettings
from pointatlas_kit.assembler import Assembler
from pointatlas_kit.fields import FieldLayout
from pointatlas_kit.streamed_tangent import (chart_groups, morton_order, streamed_tangent,
                                             sum_block_parts)
from pointatlas_kit.surface_model import atlas_factories, build_surface_model
from pointatlas_physics.kirchhoff_love.shell_energy import DISPLACEMENT, ShellEnergy


def ellipsoid(n: int) -> np.ndarray:
    """Quasi-uniform points on x²/1.2² + y² + z²/0.8² = 1 (a Fibonacci lattice mapped
    radially), made here and not by a project source."""
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    r = np.sqrt(1 - z * z)
    t = np.pi * (1 + 5**0.5) * k
    return np.c_[1.2 * r * np.cos(t), r * np.sin(t), 0.8 * z]


@pytest.fixture(scope="module")
def model():
    s = AtlasSettings(markers_per_patch=100)
    m = build_surface_model(PointCloud(points=ellipsoid(1200), name="ellipsoid"), s,
                            order=2, block=3, **atlas_factories(None, s))
    layout = FieldLayout([DISPLACEMENT], m.quadrature.n_nodes)
    return m, layout, [ShellEnergy(2.0e5, 0.3, 0.02)]


def relative_difference(A, B) -> float:
    return abs(A - B).max() / abs(B).max()


@pytest.mark.parametrize("deformed", [False, True])
def test_the_streamed_tangent_is_the_kits_tangent(model, deformed):
    """Several chart groups (a few thousand Gauss points each); the model's quadrature holds
    the basis the atlas built, the groups rebuild it from the charts."""
    m, layout, energies = model
    rng = np.random.default_rng(1)
    U = 0.01 * rng.normal(size=(layout.n_nodes, 3)) if deformed else None
    expected = Assembler(m.quadrature, layout, energies).tangent(
        np.zeros((layout.n_nodes, 3)) if U is None else U)
    assert len(chart_groups(m.atlas.quadrature_, 3000)) >= 4
    got = streamed_tangent(m.atlas, layout, energies, U, group_points=3000)
    assert got.shape == expected.shape and got.blocksize == (3, 3)
    assert relative_difference(got.tocsr(), expected) <= 1e-12
    # one group is the whole atlas: the same sums in another order
    whole = streamed_tangent(m.atlas, layout, energies, U, group_points=10**9)
    assert relative_difference(whole.tocsr(), expected) <= 1e-12
    # the block upper triangle: K = U + Uᵀ − blockdiag U
    up = streamed_tangent(m.atlas, layout, energies, U, group_points=3000, upper=True)
    assert len(up.indices) < 0.6 * len(got.indices)
    rows = np.repeat(np.arange(layout.n_nodes), np.diff(up.indptr))
    assert (up.indices >= rows).all()
    on = up.indices == rows
    ptr = np.r_[0, np.cumsum(np.bincount(rows[on], minlength=layout.n_nodes))]
    diag = bsr_matrix((up.data[on], up.indices[on], ptr), shape=up.shape).tocsr()
    up = up.tocsr()
    assert relative_difference(up + up.T - diag, expected) <= 1e-12


def test_on_a_dask_cluster_the_streamed_tangent_is_the_local_one(model):
    distributed = pytest.importorskip("distributed")
    from pointatlas_executors.dask_executor import DaskExecutor

    m, layout, energies = model
    local = streamed_tangent(m.atlas, layout, energies, group_points=3000).tocsr()
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=":0",
                                  env={"NUMBA_NUM_THREADS": "1"}) as cluster:
        with using_executor(DaskExecutor(scheduler_address=cluster.scheduler_address)):
            remote = streamed_tangent(m.atlas, layout, energies, group_points=3000).tocsr()
    assert relative_difference(remote, local) <= 1e-12


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10**6), st.integers(1, 5), st.integers(1, 4))
def test_the_block_sum_is_scipys_sum(seed, n_parts, block):
    rng = np.random.default_rng(seed)
    n = 7
    parts, expected, pairs = [], np.zeros((n * block, n * block)), set()
    for _ in range(n_parts):
        dense = (rng.random((n, n)) < 0.4) * 1.0
        rows = np.flatnonzero(dense.any(axis=1))
        lengths = dense[rows].sum(axis=1).astype(np.int64)
        cols = np.concatenate([np.flatnonzero(dense[r]) for r in rows]) if rows.size else \
            np.zeros(0, np.int64)
        data = rng.normal(size=(len(cols), block, block))
        parts.append((rows, lengths, cols.astype(np.int64), data))
        r_of = np.repeat(rows, lengths)
        pairs |= set(zip(r_of.tolist(), cols.tolist()))
        for (a, b), d in zip(zip(r_of, cols), data):
            expected[a * block:(a + 1) * block, b * block:(b + 1) * block] += d
    got = sum_block_parts(parts, n, block)
    assert parts == []  # freed as copied
    np.testing.assert_allclose(got.toarray(), expected, rtol=0, atol=1e-14)
    assert len(got.indices) == len(pairs)  # one block per node pair, duplicates summed


def test_morton_order_keeps_neighbours_close():
    """On a shuffled 16 × 16 grid every point appears once, and each run of 4^k consecutive
    points of the order is a 2^k × 2^k square (the Z-curve's nesting)."""
    g = np.stack(np.meshgrid(np.arange(16.0), np.arange(16.0)), -1).reshape(-1, 2)
    g = g[np.random.default_rng(0).permutation(len(g))]
    o = morton_order(g)
    assert sorted(o) == list(range(len(g)))
    for k in (1, 2, 3):
        runs = g[o].reshape(-1, 4**k, 2)
        assert (np.ptp(runs, axis=1) == 2**k - 1).all()
    # the same grid placed in R^7 by an orthonormal map: ordered in its principal plane
    # (turned within it), 21 bits per axis (no shift beyond the 64-bit code): consecutive
    # points stay close (1.9 apart on average; a random order: 8.6)
    Q = np.linalg.qr(np.random.default_rng(2).normal(size=(7, 2)))[0]
    o7 = morton_order(g @ Q.T)
    assert sorted(o7) == list(range(len(g)))
    assert np.linalg.norm(np.diff(g[o7], axis=0), axis=1).mean() < 2.5


def test_an_atlas_without_quadrature_is_refused_in_one_line():
    atlas = Atlas(AtlasSettings(), None, None, None)
    with pytest.raises(InputError, match="call atlas.build_quadrature"):
        streamed_tangent(atlas, FieldLayout([DISPLACEMENT], 4), [ShellEnergy(1.0, 0.3, 0.1)])
    with pytest.raises(InputError, match="group_points must be ≥ 1"):
        chart_groups([object()], 0)
