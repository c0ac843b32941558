"""Support-neighbour search: cell lists with per-node radii against brute force."""
import numpy as np
import pytest

from pointatlas_approximants.support import SupportGrid


def _brute_force(nodes, radii, x):
    d2 = ((x[:, None, :] - nodes[None, :, :]) ** 2).sum(axis=2)
    return [np.flatnonzero(row < radii**2) for row in d2]


@pytest.mark.parametrize("d", [1, 2, 3])
def test_query_equals_brute_force_with_varying_radii(d):
    rng = np.random.default_rng(d)
    nodes = rng.random((300, d)) ** 2  # clustered towards the origin
    radii = 0.05 + 0.25 * rng.random(300)
    x = rng.random((400, d)) * 1.2 - 0.1
    x[:5] = nodes[:5]  # points on nodes
    x[5:10] = nodes[5:10] + radii[5:10, None] * (1 - 1e-9) / np.sqrt(d)  # just inside
    indptr, indices = SupportGrid(nodes, radii).query(x)
    expected = _brute_force(nodes, radii, x)
    for i, exp in enumerate(expected):
        np.testing.assert_array_equal(indices[indptr[i]:indptr[i + 1]], exp)  # sorted nodes


def test_cells_order_points_by_cell_and_flag_points_off_the_grid():
    rng = np.random.default_rng(7)
    nodes = rng.random((200, 2))
    grid = SupportGrid(nodes, np.full(200, 0.1))
    x = rng.random((500, 2)) * 3 - 1
    x[3] = np.nan
    x[4, 1] = np.inf
    cells = grid.cells(x)
    c = (x - grid.lo) / grid.cell
    on_grid = np.all((c >= 0) & (c < grid.shape), axis=1)
    cell_index = np.clip(np.nan_to_num(c), 0, grid.shape - 1).astype(np.int64)
    expected = np.where(on_grid, cell_index @ grid.strides, -1)
    np.testing.assert_array_equal(cells.cell, expected)
    assert cells.cell[3] == cells.cell[4] == -1
    np.testing.assert_array_equal(cells.visit, np.argsort(expected, kind="stable"))
    assert (np.diff(cells.count())[~on_grid] == 0).all()


def test_visit_order_is_the_stable_cell_order_on_both_paths():
    """Few points on a large grid take the comparison sort (the counting sort would touch
    every cell); both paths give np.argsort(cid, kind='stable'), so results are unchanged."""
    from pointatlas_approximants.support import _sort_by_cell, visit_order

    rng = np.random.default_rng(3)
    n_cells = 5000
    for m in (10, 400, 30000):  # argsort path, argsort path, counting path
        cid = rng.integers(-1, n_cells, m)
        expected = np.argsort(cid, kind="stable")
        np.testing.assert_array_equal(visit_order(cid, n_cells), expected)
        np.testing.assert_array_equal(_sort_by_cell(cid, n_cells), expected)


def test_a_chart_sized_query_on_a_large_grid_does_not_scan_the_grid(monkeypatch):
    """A surface in 3-D fills few of its grid's cells (up to 16 per node): a query of 50
    points must not run the counting sort over every cell, which made the atlas's
    per-chart partition-of-unity evaluations cost O(N) each (O(N²) in all)."""
    from pointatlas_approximants import support

    rng = np.random.default_rng(4)
    nodes = rng.normal(size=(20_000, 3))
    nodes /= np.linalg.norm(nodes, axis=1, keepdims=True)  # a sphere: most cells are empty
    grid = SupportGrid(nodes, np.full(len(nodes), 0.03))
    assert len(grid.starts) - 1 > 10 * len(nodes)
    expected = grid.query(nodes[:50])

    def counting_sort(cid, n_cells):
        raise AssertionError(f"counting sort over {n_cells} cells for {len(cid)} points")

    monkeypatch.setattr(support, "_sort_by_cell", counting_sort)
    indptr, indices = grid.query(nodes[:50])
    np.testing.assert_array_equal(indptr, expected[0])
    np.testing.assert_array_equal(indices, expected[1])
