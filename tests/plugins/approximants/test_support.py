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
