"""The load-path Dataset: per-point variables, errors before/after a snap, timing, figures."""
from types import SimpleNamespace

import numpy as np
import pytest

from pointatlas_solvers.increment import Increment
from pointatlas_studies.shell_path_results import first_crossing, path_dataset, path_figures


def _study(**kw):
    base = dict(monitor_magnitude=False, monitor_variable="radial_displacement",
                monitor_variables=["w_A", "u_B"], reference_load_factors=[0.25, 0.5, 0.75],
                reference_values=[1.0, 2.0, 3.0, -1.0, -2.0, -3.3], reference_label="table",
                reference_split_level=0.5)
    base.update(kw)
    return SimpleNamespace(**base)


def _records(lams, stable=True):
    return [Increment(lam, np.zeros((4, 3)), 3, [1e-9], {"total": 1.0, "membrane": 0.6,
                                                          "bending": 0.4}, 0, stable, 2.0)
            for lam in lams]


def test_per_point_variables_split_errors_and_time_per_iteration():
    lams = [0.25, 0.5, 0.75]
    values = [[1.0, -1.0], [2.0, -2.0], [3.0, -3.0]]   # u_B misses the last level by 10 %
    recs = _records(lams)
    ds = path_dataset(_study(), 12, np.zeros((5, 3)), recs, values, ["A", "B"], [],
                      [(lam * 100.0, "force") for lam in lams])
    assert ds["u_B"].dims == ("increment",) and ds["u_B"].values.tolist() == [-1, -2, -3]
    assert ds["w_A"].values.tolist() == [1, 2, 3]
    assert float(ds["max_relative_error_before"]) == pytest.approx(0.0)
    assert float(ds["max_relative_error_after"]) == pytest.approx(0.3 / 3.3)
    assert float(ds["max_relative_error"]) == pytest.approx(0.3 / 3.3)
    assert float(ds["time_per_newton_iteration"]) == pytest.approx(2.0 / 3)
    assert ds["load"].values.tolist() == pytest.approx([25.0, 50.0, 75.0])


def test_first_crossing_reports_what_force_control_sees():
    # a path over a limit point at λ = 0.5, down to 0.3, and up again to 1
    lam = [0.25, 0.5, 0.4, 0.3, 0.6, 1.0]
    w = [1.0, 2.0, 2.5, 3.0, 4.0, 5.0]
    got = first_crossing([0.25, 0.45, 0.55, 1.0, 1.2], lam, w)
    assert got[:4] == pytest.approx([1.0, 1.8, 3.0 + 0.25 / 0.3, 5.0])
    assert np.isnan(got[4])
    # a level equal to the last load factor up to round-off is reached
    assert first_crossing([1.0], [0.3, 0.6, 0.9 + 0.1 - 1e-15], [1, 2, 3])[0] == pytest.approx(3)


def test_figures_mark_unstable_increments_and_draw_snapshots():
    lams = [0.25, 0.5, 0.75, 1.0]
    recs = _records(lams)
    recs[2].stable = False
    n = 60
    rng = np.random.default_rng(0)
    pts = rng.normal(size=(n, 3))
    fields = [(0.1 * k * pts, np.column_stack([rng.random(n), rng.random(n),
                                               2 * rng.random(n)])) for k in range(4)]
    ds = path_dataset(_study(monitor_variables=[], reference_load_factors=[]), 12, pts, recs,
                      [[0.1 * k, 0.2 * k] for k in range(4)], ["A", "B"], fields,
                      [(lam, "force") for lam in lams])
    assert ds["energy_density"].dims == ("increment", "sample")
    assert ds["displacement_field"].dims == ("increment", "sample", "dim")
    figs = path_figures(ds)
    assert len(figs) == 2 and figs[1][1][:4] == b"\x89PNG"
    ax = figs[0][1].axes[0]
    assert any(line.get_label().startswith("unstable") for line in ax.get_lines())
