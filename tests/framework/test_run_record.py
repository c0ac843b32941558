"""The run pipeline keeps the catalog truthful: failures after the study, broken catalogs,
leftovers of killed writes (issue 15, defects 4, 6 and 8)."""
import json
import os
import sqlite3

import pytest

import pointatlas
from pointatlas import run as run_module
from pointatlas.catalog import Catalog
from pointatlas.run import run_study

CONFIG = {"seed": 7, "outputs_root": None, "source": {"n_points": 300},
          "embedder": {"n_components": 2}, "study": {}}
CHOICES = {"source": "swiss_roll", "embedder": "pca", "study": "embedding"}


def _run(tmp_path, run_dir="run", **config):
    cfg = {**CONFIG, "outputs_root": str(tmp_path / "outputs"), **config}
    return run_study(config=cfg, choices=CHOICES, overrides=["embedder=pca"],
                     run_dir=tmp_path / run_dir)


def test_a_failure_after_the_study_marks_the_run_failed(tmp_path, monkeypatch):
    def broken_write(*args, **kwargs):
        raise TypeError("illegal data type for attribute b'seed'")

    monkeypatch.setattr(run_module, "write_results", broken_write)
    with pytest.raises(TypeError):
        _run(tmp_path)
    (record,) = Catalog(tmp_path / "outputs" / "catalog.sqlite").runs()
    assert record.status == "failed" and "illegal data type" in record.error
    assert "illegal data type" in (tmp_path / "run" / "error.txt").read_text()


def test_run_json_names_the_run_and_its_process(tmp_path):
    _run(tmp_path)
    info = json.loads((tmp_path / "run" / "run.json").read_text())
    (record,) = Catalog(tmp_path / "outputs" / "catalog.sqlite").runs()
    assert info["run_id"] == record.id and info["pid"] == os.getpid() == record.pid
    assert record.status == "completed"


def test_a_corrupt_catalog_does_not_stop_the_run(tmp_path, capfd):
    (tmp_path / "outputs").mkdir()
    (tmp_path / "outputs" / "catalog.sqlite").write_bytes(b"this is not sqlite" * 100)
    path = _run(tmp_path)
    assert pointatlas.open_run(path).attrs["status"] == "completed"
    err = capfd.readouterr().err
    warnings = [line for line in err.splitlines() if "catalog" in line and "cannot be used" in line]
    assert len(warnings) == 1 and "pointatlas-runs repair" in warnings[0]


def test_leftover_temporary_files_are_removed_by_the_next_run(tmp_path):
    run_dir = tmp_path / "run"
    run_dir.mkdir()
    for name in (".results.nc.abc123.tmp", "increments.partial.nc"):
        (run_dir / name).write_bytes(b"x" * 1000)
    _run(tmp_path)
    assert not (run_dir / ".results.nc.abc123.tmp").exists()
    assert not (run_dir / "increments.partial.nc").exists()
    assert (run_dir / "results.nc").is_file()


def test_results_follow_the_umask(tmp_path):
    old = os.umask(0o027)
    try:
        path = _run(tmp_path)
    finally:
        os.umask(old)
    assert oct(path.stat().st_mode & 0o777) == oct(0o640)


def test_the_catalog_migrates_from_schema_1(tmp_path):
    path = tmp_path / "catalog.sqlite"
    with sqlite3.connect(path) as conn:
        conn.executescript("""
            CREATE TABLE schema_version (version INTEGER NOT NULL);
            INSERT INTO schema_version VALUES (1);
            CREATE TABLE runs (id TEXT PRIMARY KEY, experiment TEXT NOT NULL,
              overrides TEXT NOT NULL DEFAULT '[]', params TEXT NOT NULL DEFAULT '{}',
              status TEXT NOT NULL, start_time TEXT, end_time TEXT, wall_time_s REAL, path TEXT,
              git_commit TEXT NOT NULL DEFAULT '', error TEXT);
            CREATE TABLE metrics (run_id TEXT NOT NULL, name TEXT NOT NULL, value REAL,
              PRIMARY KEY (run_id, name));
            INSERT INTO runs (id, experiment, status) VALUES ('old', 'e', 'running');
        """)
    (record,) = Catalog(path).runs()
    assert record.id == "old" and record.status == "running" and record.pid is None


def test_results_with_warnings_are_recorded_as_such(tmp_path, monkeypatch):
    from pointatlas_studies.embedding import EmbeddingStudy

    original = EmbeddingStudy.run

    def run_with_warning(self, ctx):
        ds = original(self, ctx)
        ds.attrs["warnings"] = "2 patches failed the chart test (allowed by the user)"
        return ds

    monkeypatch.setattr(EmbeddingStudy, "run", run_with_warning)
    path = _run(tmp_path)
    (record,) = Catalog(tmp_path / "outputs" / "catalog.sqlite").runs()
    assert record.status == "completed_with_warnings" and "2 patches" in record.error
    assert pointatlas.open_run(path).attrs["status"] == "completed_with_warnings"
