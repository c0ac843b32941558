"""Tests of the run catalog (pointatlas.catalog): recording, filters, missing dirs, concurrency."""
from __future__ import annotations

import math
import multiprocessing
import sqlite3
import subprocess
import sys

import pytest

from pointatlas.catalog import (
    SCHEMA_VERSION,
    Catalog,
    RunRecord,
    catalog_path,
    parse_metric,
    parse_where,
)
from pointatlas.errors import ConfigError, InputError, SchemaError


def _record(cat: Catalog, run_id: str, *, experiment="swiss_isomap", overrides=(), metrics=None,
            status="completed", path=None, params=None, start="2026-11-23T10:00:00+00:00"):
    cat.start(run_id=run_id, experiment=experiment, overrides=list(overrides), path=path,
              git_commit="abc123", start_time=start, params=params)
    if status != "running":
        cat.finish(run_id, status=status, end_time="2026-11-23T10:00:05+00:00", wall_time_s=5.0,
                   metrics=metrics or {}, error=None if status == "completed" else "boom")


@pytest.fixture
def cat(tmp_path):
    return Catalog(catalog_path(tmp_path / "outputs"))


def test_catalog_path_and_creation(tmp_path):
    path = catalog_path(tmp_path / "a" / "b")
    assert path == tmp_path / "a" / "b" / "catalog.sqlite"
    Catalog(path)
    assert path.is_file()
    with sqlite3.connect(path) as conn:
        assert conn.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
        assert conn.execute("SELECT version FROM schema_version").fetchall() == [(SCHEMA_VERSION,)]
    Catalog(path)  # reopening keeps one version row
    with sqlite3.connect(path) as conn:
        assert conn.execute("SELECT COUNT(*) FROM schema_version").fetchone()[0] == 1


def test_newer_schema_is_refused(tmp_path):
    path = tmp_path / "catalog.sqlite"
    Catalog(path)
    with sqlite3.connect(path) as conn:
        conn.execute("UPDATE schema_version SET version=?", (SCHEMA_VERSION + 1,))
    with pytest.raises(SchemaError, match="upgrade pointatlas"):
        Catalog(path)


def test_start_finish_roundtrip(cat, tmp_path):
    run_dir = tmp_path / "outputs" / "run1"
    run_dir.mkdir(parents=True)
    cat.start(run_id="run1", experiment="swiss_isomap", overrides=["embedder=isomap", "seed=3"],
              path=str(run_dir), git_commit="deadbeef", start_time="2026-11-23T10:00:00+00:00",
              params={"source.n_points": "2000"})
    rec = cat.get("run1")
    assert isinstance(rec, RunRecord)
    assert rec.status == "running" and rec.end_time is None and rec.metrics == {}
    cat.finish("run1", status="completed", end_time="2026-11-23T10:01:00+00:00", wall_time_s=60.0,
               metrics={"stress": 3.5, "relative_error": 1e-4, "bad": float("nan")})
    rec = cat.get("run1")
    assert rec.status == "completed" == rec.recorded_status
    assert rec.overrides == ["embedder=isomap", "seed=3"]
    assert rec.params == {"source.n_points": "2000"}
    assert rec.wall_time_s == 60.0 and rec.end_time == "2026-11-23T10:01:00+00:00"
    assert rec.metrics["stress"] == 3.5 and rec.metrics["relative_error"] == 1e-4
    assert math.isnan(rec.metrics["bad"])
    assert rec.path == str(run_dir) and rec.git_commit == "deadbeef" and rec.error is None


def test_finish_failed_and_invalid(cat):
    _record(cat, "r1", status="failed")
    rec = cat.get("r1")
    assert rec.status == "failed" and rec.error == "boom"
    with pytest.raises(ConfigError, match="completed"):
        cat.finish("r1", status="done", end_time="x", wall_time_s=1.0, metrics={})
    with pytest.raises(InputError, match="Catalog.start"):
        cat.finish("nope", status="completed", end_time="x", wall_time_s=1.0, metrics={})


def test_record_failure(cat):
    cat.record_failure(run_id="bad1", experiment="swiss_isomap", overrides=["embedder=nope"],
                       path=None, git_commit="", start_time="2026-11-23T10:00:00+00:00",
                       end_time="2026-11-23T10:00:02.5+00:00", error="unknown embedder 'nope'")
    rec = cat.get("bad1")
    assert rec.status == "failed" and rec.error == "unknown embedder 'nope'"
    assert rec.wall_time_s == pytest.approx(2.5) and rec.path is None


def test_restart_same_id_replaces_metrics(cat):
    _record(cat, "r1", metrics={"stress": 1.0, "old": 2.0})
    _record(cat, "r1", metrics={"stress": 9.0})
    assert [r.id for r in cat.runs()] == ["r1"]
    assert cat.get("r1").metrics == {"stress": 9.0}


def test_get_by_prefix(cat):
    _record(cat, "abc111")
    _record(cat, "abc222")
    _record(cat, "abc")
    assert cat.get("abc1").id == "abc111"
    assert cat.get("abc").id == "abc"  # exact match wins over prefix
    with pytest.raises(InputError, match="ambiguous"):
        cat.get("ab")
    with pytest.raises(InputError, match="no run"):
        cat.get("zzz")
    with pytest.raises(InputError, match="no run"):
        cat.get("a%")  # no LIKE wildcards


def test_filters(cat):
    _record(cat, "r1", overrides=["embedder=isomap", "source.n_points=2000"], metrics={"stress": 5.0},
            start="2026-11-23T10:00:01")
    _record(cat, "r2", overrides=["embedder=lle", "+source.n_points=1000"], metrics={"stress": 20.0},
            start="2026-11-23T10:00:02")
    _record(cat, "r3", experiment="torus", overrides=[], params={"embedder": "isomap"},
            metrics={"relative_error": 1e-3, "area": 4.0}, start="2026-11-23T10:00:03")
    _record(cat, "r4", overrides=["embedder=isomap"], status="failed", start="2026-11-23T10:00:04")

    def ids(**kw):
        return [r.id for r in cat.runs(**kw)]

    assert ids() == ["r1", "r2", "r3", "r4"]
    assert ids(experiment="torus") == ["r3"]
    assert ids(status="failed") == ["r4"]
    assert ids(where=["embedder=isomap"]) == ["r1", "r3", "r4"]
    assert ids(where=["source.n_points=1000"]) == ["r2"]
    assert ids(where=["source.n_points=2000.0"]) == ["r1"]  # numeric equality
    assert ids(where=["embedder=isomap", "source.n_points=2000"]) == ["r1"]
    assert ids(where=["experiment=torus"]) == ["r3"]
    assert ids(metric=["stress<10"]) == ["r1"]
    assert ids(metric=["stress>=5", "stress<=20"]) == ["r1", "r2"]
    assert ids(metric=["stress!=5"]) == ["r2"]
    assert ids(metric=["relative_error<=1e-3"]) == ["r3"]
    assert ids(metric=["relative_error<1e-3"]) == []
    assert ids(metric=["area>3"]) == ["r3"]
    assert ids(metric=["area=4"]) == ["r3"]
    assert ids(where="embedder=isomap", metric="stress < 10") == ["r1"]  # lone string accepted
    assert ids(limit=2) == ["r3", "r4"]
    assert ids(limit=0) == []


@pytest.mark.parametrize("bad", ["stress", "stress<<1", "stress<abc", "<3", "stress 3", ""])
def test_bad_metric_filter(cat, bad):
    with pytest.raises(ConfigError, match="<="):
        cat.runs(metric=[bad])


@pytest.mark.parametrize("bad", ["embedder", "=isomap", "embedder==isomap", "a b=c", ""])
def test_bad_where_filter(cat, bad):
    with pytest.raises(ConfigError, match="key=value"):
        cat.runs(where=[bad])


def test_parse_filters():
    assert parse_metric(" relative_error <= 1e-3 ").value == 1e-3
    assert parse_metric("area>3").op == ">"
    f = parse_where("++source.name='sphere'")
    assert (f.key, f.value) == ("source.name", "sphere")


def test_bad_status_filter(cat):
    with pytest.raises(ConfigError, match="missing"):
        cat.runs(status="done")


def test_missing_directory(cat, tmp_path):
    present, gone = tmp_path / "present", tmp_path / "gone"
    present.mkdir()
    gone.mkdir()
    _record(cat, "keep", path=str(present), start="1")
    _record(cat, "lost", path=str(gone), start="2")
    _record(cat, "nopath", path=None, start="3")
    gone.rmdir()
    by_id = {r.id: r for r in cat.runs()}
    assert by_id["keep"].status == "completed"
    assert by_id["lost"].status == "missing" and by_id["lost"].recorded_status == "completed"
    assert by_id["nopath"].status == "completed"
    assert [r.id for r in cat.runs(status="missing")] == ["lost"]
    assert [r.id for r in cat.runs(status="completed")] == ["keep", "nopath"]


def test_relative_path_is_stored_absolute(cat, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "rel").mkdir()
    _record(cat, "r", path="rel")
    assert cat.get("r").path == str(tmp_path / "rel")


def _writer(path: str, worker: int, n_runs: int, barrier) -> None:
    barrier.wait()
    cat = Catalog(path)
    for i in range(n_runs):
        run_id = f"w{worker}-r{i:02d}"
        cat.start(run_id=run_id, experiment="sweep", overrides=[f"seed={i}", f"worker={worker}"],
                  path=None, git_commit="", start_time=f"2026-11-23T10:{worker:02d}:{i:02d}")
        cat.finish(run_id, status="completed", end_time="2026-11-23T11:00:00", wall_time_s=0.1,
                   metrics={"stress": float(i), "worker": float(worker)})


def test_concurrent_writers(tmp_path):
    """8 processes x 25 runs each, all creating the (fresh) catalog at once: no row lost."""
    path = str(catalog_path(tmp_path / "outputs"))
    method = "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"
    ctx = multiprocessing.get_context(method)
    n_workers, n_runs = 8, 25
    barrier = ctx.Barrier(n_workers)
    procs = [ctx.Process(target=_writer, args=(path, w, n_runs, barrier)) for w in range(n_workers)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(timeout=120)
    assert [p.exitcode for p in procs] == [0] * n_workers
    runs = Catalog(path).runs()
    assert len(runs) == n_workers * n_runs
    assert {r.id for r in runs} == {f"w{w}-r{i:02d}" for w in range(n_workers) for i in range(n_runs)}
    assert all(r.status == "completed" for r in runs)
    assert all(r.metrics == {"stress": float(r.id[-2:]), "worker": float(r.id[1])} for r in runs)
    assert len(Catalog(path).runs(where=["worker=3"], metric=["stress<10"])) == 10


def test_import_is_light():
    code = ("import sys, pointatlas.catalog, pointatlas.runs_cli\n"
            "heavy = [m for m in ('xarray', 'numpy', 'matplotlib', 'pyvista', 'numba') if m in sys.modules]\n"
            "assert not heavy, heavy\n")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60)
