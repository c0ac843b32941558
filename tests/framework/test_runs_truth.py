"""The catalog tells the truth: start-up typos are not runs, runs carry their experiment and
resolved settings, numbers tell runs apart, runs can be removed and rerun."""
import json

import pytest
import xarray as xr

from pointatlas.catalog import Catalog
from pointatlas.runs_format import distinct_digits, number
from pointatlas.run_filters import flatten_settings

PLATE = ("experiment=shell_plate", "source.n_points=121")


def test_digits_tell_values_apart():
    assert [number(v, distinct_digits([1.22589, 1.2257, 1.22571])) for v in
            (1.22589, 1.2257, 1.22571)] == ["1.22589", "1.2257", "1.22571"]
    assert distinct_digits([1.0, 1.0, None, float("nan")]) == 4
    assert distinct_digits([0.1 + 0.2, 0.3]) == 17


def test_flatten_settings_spells_values_as_overrides():
    flat = flatten_settings({"source": {"n_points": 441, "path": None, "jitter": 0.5,
                                        "closed": True, "centre": [0.0, 1.0]}, "seed": 3})
    assert flat == {"source.n_points": "441", "source.path": "null", "source.jitter": "0.5",
                    "source.closed": "true", "source.centre": "[0.0, 1.0]", "seed": "3"}


def _runs(run_cli, root, *args):
    out = run_cli("pointatlas-runs", *args, "--root", str(root), cwd=root.parent)
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_a_typo_is_rejected_not_a_run(run_cli, tmp_path):
    out = run_cli("pointatlas", "source.n_pionts=5", f"outputs_root={tmp_path / 'out'}",
                  cwd=tmp_path)
    assert out.returncode == 2
    assert _runs(run_cli, tmp_path / "out", "list").strip() == "no runs match"
    rows = json.loads(_runs(run_cli, tmp_path / "out", "list", "--all", "--format", "json"))
    assert [(r["status"], r["experiment"]) for r in rows] == [("rejected", "sphere_willmore")]
    assert "n_pionts" in rows[0]["error"]


def test_resolved_settings_digits_rm_and_rerun(run_cli, tmp_path):
    root = tmp_path / "out"
    first = run_cli("pointatlas", *PLATE, f"outputs_root={root}", cwd=tmp_path)
    assert first.returncode == 0, first.stderr[-2000:]
    assert f"outputs root: {root}" in first.stdout + first.stderr
    second = run_cli("pointatlas", *PLATE, "physics.poisson_ratio=0.25", f"outputs_root={root}",
                     cwd=tmp_path)
    assert second.returncode == 0, second.stderr[-2000:]
    catalog = Catalog(root / "catalog.sqlite")
    runs = catalog.runs()
    assert [r.experiment for r in runs] == ["shell_plate", "shell_plate"]
    assert runs[0].params["physics.poisson_ratio"] == "0.3"  # kept from the experiment
    # a default kept by the run is seen by filters and compare
    assert len(catalog.runs(where=["n_points=121"])) == 2
    assert [r.id for r in catalog.runs(where=["poisson_ratio=0.3"])] == [runs[0].id]
    compared = json.loads(_runs(run_cli, root, "compare", runs[0].id, runs[1].id,
                                "--format", "json"))
    assert compared["differing"]["physics.poisson_ratio"] == ["0.3", "0.25"]
    text = _runs(run_cli, root, "compare", runs[0].id, runs[1].id)
    shown = [line.split()[1:] for line in text.splitlines() if line.startswith("displacement ")]
    assert len(shown) == 1 and shown[0][0] != shown[0][1]
    a, b = (r.metrics["displacement"] for r in runs)
    assert float(shown[0][0]) == pytest.approx(a, rel=1e-3)
    # rerun: a new run with the same overrides and the same numbers
    rerun = run_cli("pointatlas-runs", "rerun", runs[1].id[:15], "--root", str(root),
                    cwd=tmp_path)
    assert rerun.returncode == 0, rerun.stderr[-2000:]
    again = catalog.runs()[-1]
    assert again.id not in (runs[0].id, runs[1].id)
    assert again.metrics["displacement"] == pytest.approx(b, rel=1e-12)
    # rm: the row and the run directory go
    folder = runs[0].path
    _runs(run_cli, root, "rm", runs[0].id)
    assert runs[0].id not in catalog.ids()
    assert not (tmp_path / folder).exists()
    assert xr.open_dataset(next(p for p in root.glob("runs/*/*/results.nc")))  # others stay
