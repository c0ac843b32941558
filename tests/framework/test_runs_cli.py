"""Tests of `pointatlas-runs` (pointatlas.runs_cli), run in-process through main([...])."""
from __future__ import annotations

import json

import pytest

from pointatlas.catalog import Catalog, catalog_path
from pointatlas.runs_cli import main, short_ids


@pytest.fixture
def root(tmp_path):
    """An outputs root with four fake runs: two isomap, one lle, one failed-before-start."""
    root = tmp_path / "outputs"
    cat = Catalog(catalog_path(root))
    for i, (run_id, embedder, n, metrics) in enumerate([
        ("20261123-aaaa1111", "isomap", "2000", {"stress": 5.0, "relative_error": 1e-4}),
        ("20261123-aaaa2222", "isomap", "1000", {"stress": 12.0, "relative_error": 2e-3}),
        ("20261123-bbbb3333", "lle", "2000", {"stress": float("nan"), "area": 4.0}),
    ]):
        run_dir = root / run_id
        run_dir.mkdir(parents=True)
        cat.start(run_id=run_id, experiment="swiss", overrides=[f"embedder={embedder}",
                  f"source.n_points={n}"], path=str(run_dir), git_commit="c0ffee",
                  start_time=f"2026-11-23T10:0{i}:00+00:00", params={"seed": "0"})
        cat.finish(run_id, status="completed", end_time=f"2026-11-23T10:0{i}:30+00:00",
                   wall_time_s=30.0 + i, metrics=metrics)
    cat.record_failure(run_id="20261123-cccc4444", experiment="torus", overrides=["embedder=nope"],
                       path=None, git_commit="c0ffee", start_time="2026-11-23T10:09:00+00:00",
                       end_time="2026-11-23T10:09:01+00:00", error="unknown embedder 'nope'")
    return root


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_list_table(root, capsys):
    code, out, err = run(capsys, "list", "--root", str(root))
    assert code == 0 and err == ""
    lines = out.splitlines()
    assert lines[0].split()[:4] == ["id", "experiment", "status", "start"]
    body = lines[2:]
    assert len(body) == 4
    assert body[0].startswith("20261123-aaaa1 ")  # shortest unique prefix (>= 8 chars)
    assert "embedder=isomap source.n_points=2000" in body[0]
    assert "stress=5" in body[0] and "relative_error=0.0001" in body[0]
    assert "30.0 s" in body[0] and "2026-11-23 10:00:00" in body[0]
    assert "failed" in body[3] and "torus" in body[3]


def test_list_root_option_before_subcommand_and_env(root, capsys, monkeypatch):
    code, out, _ = run(capsys, "--root", str(root), "list", "--format", "json")
    assert code == 0 and len(json.loads(out)) == 4
    monkeypatch.setenv("POINTATLAS_OUTPUTS", str(root))
    code, out, _ = run(capsys, "list", "--format", "json")
    assert code == 0 and len(json.loads(out)) == 4


def test_default_root_is_cwd_outputs(root, capsys, monkeypatch):
    monkeypatch.delenv("POINTATLAS_OUTPUTS", raising=False)
    monkeypatch.chdir(root.parent)
    code, out, _ = run(capsys, "list", "--format", "json")
    assert code == 0 and len(json.loads(out)) == 4


def test_list_json_and_filters(root, capsys):
    code, out, err = run(capsys, "list", "--root", str(root), "--format", "json",
                         "--where", "embedder=isomap", "--metric", "stress<10")
    assert code == 0 and err == ""
    data = json.loads(out)
    assert [d["id"] for d in data] == ["20261123-aaaa1111"]
    assert data[0]["metrics"] == {"stress": 5.0, "relative_error": 1e-4}
    assert data[0]["overrides"] == ["embedder=isomap", "source.n_points=2000"]

    code, out, _ = run(capsys, "list", "--root", str(root), "--format", "json",
                       "--where", "source.n_points=2000")
    assert [d["id"][-4:] for d in json.loads(out)] == ["1111", "3333"]
    code, out, _ = run(capsys, "list", "--root", str(root), "--format", "json",
                       "--experiment", "torus")
    assert [d["status"] for d in json.loads(out)] == ["failed"]
    code, out, _ = run(capsys, "list", "--root", str(root), "--format", "json", "--status", "failed")
    assert [d["experiment"] for d in json.loads(out)] == ["torus"]
    code, out, _ = run(capsys, "list", "--root", str(root), "--format", "json", "--limit", "1")
    assert [d["id"][-4:] for d in json.loads(out)] == ["4444"]


def test_nan_metric_is_valid_json(root, capsys):
    code, out, _ = run(capsys, "show", "20261123-bbbb", "--root", str(root), "--format", "json")
    assert code == 0
    data = json.loads(out)  # strict: no NaN token
    assert "NaN" not in out and data["metrics"] == {"stress": None, "area": 4.0}


def test_missing_run_directory(root, capsys):
    (root / "20261123-aaaa2222").rmdir()
    code, out, err = run(capsys, "list", "--root", str(root))
    assert code == 0 and err == ""
    line = next(l for l in out.splitlines() if l.startswith("20261123-aaaa2"))
    assert "missing" in line
    code, out, _ = run(capsys, "list", "--root", str(root), "--status", "missing", "--format", "json")
    assert [d["id"] for d in json.loads(out)] == ["20261123-aaaa2222"]
    code, out, _ = run(capsys, "show", "20261123-aaaa2", "--root", str(root))
    assert code == 0 and "missing (recorded: completed)" in out


def test_empty_result(root, capsys):
    code, out, _ = run(capsys, "list", "--root", str(root), "--metric", "stress<0")
    assert code == 0 and out.strip() == "no runs match"
    code, out, _ = run(capsys, "list", "--root", str(root), "--metric", "stress<0", "--format", "json")
    assert json.loads(out) == []


def test_show(root, capsys):
    code, out, err = run(capsys, "show", "20261123-aaaa1", "--root", str(root))
    assert code == 0 and err == ""
    for text in ["20261123-aaaa1111", "swiss", "completed", "c0ffee", "embedder=isomap",
                 "seed = 0", "stress", "relative_error", "2026-11-23T10:00:30+00:00", "30.0 s"]:
        assert text in out
    code, out, _ = run(capsys, "show", "20261123-cccc", "--root", str(root), "--format", "json")
    data = json.loads(out)
    assert set(data) >= {"id", "experiment", "overrides", "params", "status", "start_time",
                         "end_time", "wall_time_s", "metrics", "path", "git_commit", "error"}
    assert data["error"] == "unknown embedder 'nope'" and data["wall_time_s"] == 1.0


def test_compare(root, capsys):
    code, out, err = run(capsys, "compare", "20261123-aaaa1", "20261123-aaaa2", "20261123-bbbb",
                         "--root", str(root))
    assert code == 0 and err == ""
    assert "differing setting" in out and "source.n_points" in out and "embedder" in out
    assert "seed" not in out.split("differing setting")[1].split("metric")[0]  # equal -> hidden
    metric_rows = {l.split()[0]: l.split()[1:] for l in out.split("\nmetric")[1].splitlines()[2:]}
    assert metric_rows["stress"] == ["5", "12", "nan"]
    assert metric_rows["area"] == ["-", "-", "4"]

    code, out, _ = run(capsys, "compare", "20261123-aaaa1", "20261123-bbbb", "--root", str(root),
                       "--format", "json")
    data = json.loads(out)
    assert data["runs"] == ["20261123-aaaa1111", "20261123-bbbb3333"]
    assert data["differing"] == {"embedder": ["isomap", "lle"]}
    assert data["metrics"]["stress"] == [5.0, None]
    assert data["metrics"]["relative_error"] == [1e-4, None]


def test_no_catalog(tmp_path, capsys):
    code, out, err = run(capsys, "list", "--root", str(tmp_path / "nothing"))
    assert code == 1 and out == ""
    path = catalog_path(tmp_path / "nothing")
    assert err.strip() == f"pointatlas-runs: no catalog at {path}: run `pointatlas` first or pass --root"
    assert not path.exists()  # listing never creates a catalog


@pytest.mark.parametrize("argv, expected", [
    (["list", "--metric", "stress<<3"], "bad metric filter"),
    (["list", "--where", "embedder"], "bad where filter"),
    (["show", "20261123-aaaa"], "ambiguous"),
    (["show", "zzz"], "no run"),
    (["compare", "20261123-aaaa1", "zzz"], "no run"),
])
def test_errors_one_line(root, capsys, argv, expected):
    code, out, err = run(capsys, *argv, "--root", str(root), "--format", "json")
    assert code == 1 and out == ""
    assert expected in err and err.count("\n") == 1 and "Traceback" not in err


@pytest.mark.parametrize("argv", [["list", "--status", "done"], ["compare", "x"], ["frobnicate"], [],
                                  ["list", "--limit", "-1"]])
def test_usage_errors(root, capsys, argv):
    code, out, err = run(capsys, *argv, *(["--root", str(root)] if argv else []))
    assert code == 2 and out == ""
    assert err.startswith("pointatlas-runs: error:") and err.count("\n") == 1


def test_corrupt_catalog(tmp_path, capsys):
    catalog_path(tmp_path).write_bytes(b"this is not sqlite" * 100)
    code, out, err = run(capsys, "list", "--root", str(tmp_path))
    assert code == 1 and out == "" and err.count("\n") == 1


def test_help(capsys):
    code, out, _ = run(capsys, "--help")
    assert code == 0 and "list" in out and "compare" in out


def test_short_ids():
    ids = ["abcdefgh1", "abcdefgh2", "zz", "abcdxxxxxx"]
    assert short_ids(ids) == {"abcdefgh1": "abcdefgh1", "abcdefgh2": "abcdefgh2", "zz": "zz",
                              "abcdxxxxxx": "abcdxxxx"}
