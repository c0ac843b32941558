"""Reports: content, self-containment, determinism, plugin figures, sweeps, CLI errors."""
from __future__ import annotations

import base64
import json
import re
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

from pointatlas import report as report_mod
from pointatlas.report import build_run_report, build_sweep_report, render_html, write_report
from pointatlas.report_cli import main
from pointatlas.report_figures import PNG_SIGNATURE, metric_vs_param_figures, sweep_records

CONFIG = "source:\n  name: swiss_roll\n  n_points: {n}\nembedder:\n  name: isomap\n"


def make_run(n_points: int = 100, error: float | None = None, extra_overrides=()) -> xr.Dataset:
    """A results Dataset with the attrs of RESULTS_FORMAT.md (schema 1)."""
    rng = np.random.default_rng(n_points)
    error = 1.0 / n_points if error is None else error
    ds = xr.Dataset(
        {
            "points": (("point", "dim"), rng.random((n_points, 3)), {"long_name": "sample points", "units": "1"}),
            "max_error": ((), error, {"long_name": "maximum error", "units": "1",
                                      "reference": 0.0125, "reference_source": "thesis table 4.2"}),
            "fit_time": ((), 0.25, {"long_name": "fit wall time", "units": "s"}),
        },
        coords={"point": np.arange(n_points), "dim": ["x", "y", "z"]},
    )
    ds.attrs.update({
        "Conventions": "CF-1.10", "title": "swiss roll isomap", "source": "pointatlas 0.1.0",
        "history": "2026-11-23T10:00:00+00:00: pointatlas experiment=demo",
        "config": CONFIG.format(n=n_points), "overrides": json.dumps([f"source.n_points={n_points}", *extra_overrides]),
        "git_commit": "abc123", "seed": 7, "hostname": "testhost", "wall_time_s": 1.5,
        "status": "completed", "start_time": "2026-11-23T10:00:00+00:00",
        "end_time": "2026-11-23T10:00:01+00:00", "pointatlas_schema": 1, "run_id": f"run-{n_points}",
        "experiment": "demo", "study": "embedding",
        "plugins": json.dumps({"source": "swiss_roll", "embedder": "isomap", "study": "embedding"}),
        "metrics": json.dumps(["max_error", "fit_time"]),
    })
    return ds


class FakeSource:
    calls: list = []

    @classmethod
    def report_figures(cls, ds):
        from matplotlib.figure import Figure

        cls.calls.append(ds.attrs["run_id"])
        fig = Figure(figsize=(3, 2))
        ax = fig.add_subplot()
        ax.scatter(ds["points"].values[:, 0], ds["points"].values[:, 1], s=2)
        png = _tiny_png()
        return [("point cloud", fig), ("screenshot", png)]


def _tiny_png() -> bytes:
    from io import BytesIO

    from matplotlib.figure import Figure

    buf = BytesIO()
    Figure(figsize=(1, 1)).savefig(buf, format="png", dpi=20, metadata={"Software": None})
    return buf.getvalue()


@pytest.fixture
def fake_loader(monkeypatch):
    """Only 'source' resolves (to FakeSource); the other plugins fail to load."""
    FakeSource.calls = []

    def load(family, name):
        if family == "source":
            return FakeSource
        raise LookupError(f"no {family} plugin {name!r} in this test")

    monkeypatch.setattr(report_mod, "load_plugin", load)
    return FakeSource


def test_run_report_content_and_determinism(tmp_path, fake_loader):
    make_run(100).to_netcdf(tmp_path / "results.nc")
    assert main([str(tmp_path)]) == 0
    html_path, md_path = tmp_path / "report.html", tmp_path / "report.md"
    html_text, md_text = html_path.read_text(), md_path.read_text()
    for text in (html_text, md_text):
        assert "max_error" in text and "maximum error" in text and "0.01" in text  # value 1/100
        assert "0.0125" in text and "-0.2" in text  # reference and relative difference (0.01-0.0125)/0.0125
        assert "thesis table 4.2" in text
        assert "n_points: 100" in text  # resolved config
        assert "abc123" in text and "testhost" in text and "source.n_points=100" in text
        assert "skipped" in text  # embedder/study plugins could not be loaded: a note, no crash
    assert fake_loader.calls == ["run-100"]
    # self-contained HTML: two embedded PNGs, no external resource
    images = re.findall(r'<img src="data:image/png;base64,([A-Za-z0-9+/=]+)"', html_text)
    assert len(images) == 2 and all(base64.b64decode(i).startswith(PNG_SIGNATURE) for i in images)
    assert "http://" not in html_text and "https://" not in html_text and "<link" not in html_text
    # Markdown twin links PNG files relatively
    links = re.findall(r"!\[[^\]]*\]\((report_files/[^)]+\.png)\)", md_text)
    assert len(links) == 2 and all((tmp_path / link).read_bytes().startswith(PNG_SIGNATURE) for link in links)
    # regenerate: byte-identical
    before = {p.name: p.read_bytes() for p in [html_path, md_path, *(tmp_path / "report_files").iterdir()]}
    assert main([str(tmp_path), "--format", "md,html"]) == 0
    after = {p.name: p.read_bytes() for p in [html_path, md_path, *(tmp_path / "report_files").iterdir()]}
    assert before == after
    assert not list(tmp_path.glob(".*tmp"))  # no temp files left


def test_out_dir_and_single_format(tmp_path, fake_loader):
    run = tmp_path / "run"
    run.mkdir()
    make_run(50).to_netcdf(run / "results.nc")
    assert main([str(run / "results.nc"), "--out", str(tmp_path / "out"), "--format", "html"]) == 0
    assert (tmp_path / "out" / "report.html").is_file()
    assert not (tmp_path / "out" / "report.md").exists() and not (run / "report.html").exists()


def test_plugin_figure_errors_become_notes(tmp_path, monkeypatch):
    class Broken:
        @staticmethod
        def report_figures(ds):
            return [("bad", "not a figure"), ("bad png", b"not png")]

    monkeypatch.setattr(report_mod, "load_plugin", lambda family, name: Broken)
    text = render_html(build_run_report(make_run(10), tmp_path))
    assert text.count("a figure was skipped") == 6  # 3 plugins x 2 bad figures
    assert "<img" not in text


def make_sweep_dirs(root, sizes=(100, 200, 400)):
    for job, n in enumerate(sizes):
        (root / str(job)).mkdir(parents=True)
        make_run(n).to_netcdf(root / str(job) / "results.nc")


def sweep_by_hand(root, sizes=(100, 200, 400)) -> xr.Dataset:
    """What open_sweep returns for a full 1-D grid: the swept key as a dim."""
    runs = [xr.load_dataset(root / str(job) / "results.nc") for job in range(len(sizes))]
    metrics = json.loads(runs[0].attrs["metrics"])
    ds = xr.concat([r[metrics] for r in runs], dim="source.n_points")
    ds = ds.assign_coords({"source.n_points": ("source.n_points", list(sizes),
                                               {"long_name": "number of points", "units": "1"})})
    ds.attrs = dict(runs[0].attrs, sweep_params=json.dumps(["source.n_points"]))
    return ds


def test_sweep_report_generic_figures(tmp_path, fake_loader):
    make_sweep_dirs(tmp_path)
    ds = sweep_by_hand(tmp_path)
    records = sweep_records(ds)
    assert [r["source.n_points"] for r in records] == [100, 200, 400]
    assert records[2]["max_error"] == pytest.approx(1 / 400)
    figs = metric_vs_param_figures(ds)
    # fit_time is the same in every run: a constant is not plotted against the sweep
    assert [t for t, _ in figs] == ["max_error vs source.n_points"]
    assert figs[0][1].axes[0].get_xscale() == "log" and figs[0][1].axes[0].get_yscale() == "log"
    report = build_sweep_report(ds, tmp_path)
    paths = write_report(report, tmp_path)
    html_text = paths[0].read_text()
    assert "max_error vs source.n_points" in html_text and "3 runs" in html_text
    assert html_text.count("data:image/png;base64,") == 1
    assert "0.0025" in html_text  # 1/400 in the runs table
    assert fake_loader.calls == []  # FakeSource has no report_sweep_figures


def test_sweep_linear_axes_with_nonpositive_values():
    ds = xr.Dataset({"gap": ("run", [-1.0, 0.5, 2.0], {"long_name": "gap", "units": "1"})},
                    coords={"run": [0, 1, 2], "a": ("run", [1, 2, 3]), "kind": ("run", ["x", "y", "x"])},
                    attrs={"metrics": '["gap"]', "sweep_params": '["a", "kind"]'})
    figs = metric_vs_param_figures(ds)
    assert [t for t, _ in figs] == ["gap vs a"]  # 'kind' is not numeric
    ax = figs[0][1].axes[0]
    assert ax.get_xscale() == "linear" and len(ax.lines) == 2  # one line per kind


def test_cli_sweep_directory(tmp_path, fake_loader):
    pytest.importorskip("pointatlas.sweep")
    make_sweep_dirs(tmp_path)
    assert main([str(tmp_path)]) == 0
    assert "data:image/png;base64," in (tmp_path / "report.html").read_text()


def test_cli_sweep_2d_grid(tmp_path, fake_loader):
    pytest.importorskip("pointatlas.sweep")
    for job, (n, k) in enumerate([(100, 5), (100, 8), (200, 5), (200, 8)]):
        (tmp_path / str(job)).mkdir()
        make_run(n, error=k / n, extra_overrides=[f"embedder.k={k}"]).to_netcdf(tmp_path / str(job) / "results.nc")
    assert main([str(tmp_path), "--format", "md"]) == 0
    md_text = (tmp_path / "report.md").read_text()
    assert "4 runs" in md_text and "| embedder_k | source_n_points |" in md_text
    # the metric that varies against the 2 numeric params (fit_time is constant)
    assert len(re.findall(r"!\[max_error vs", md_text)) == 2
    assert "fit_time vs" not in md_text
    assert "| 8 | 200 | 0.04 |" in md_text


class FakeStudy:
    """A study with its own sweep figure (one PNG)."""

    @staticmethod
    def report_sweep_figures(ds):
        return [("study curve", _tiny_png())]


@pytest.fixture
def study_loader(monkeypatch):
    """'study' resolves to FakeStudy (it has sweep figures); the other plugins fail to load."""

    def load(family, name):
        if family == "study":
            return FakeStudy
        raise LookupError(f"no {family} plugin {name!r} in this test")

    monkeypatch.setattr(report_mod, "load_plugin", load)


@pytest.mark.parametrize("flag, n_generic", [([], 0), (["--generic-plots"], 1), (["--no-generic-plots"], 0)])
def test_cli_sweep_generic_plots_on_demand(tmp_path, study_loader, flag, n_generic):
    pytest.importorskip("pointatlas.sweep")
    make_sweep_dirs(tmp_path)
    assert main([str(tmp_path), *flag]) == 0
    html_text = (tmp_path / "report.html").read_text()
    md_text = (tmp_path / "report.md").read_text()
    # the study's figure always, first; the generic 'max_error vs source.n_points' only on demand
    assert html_text.count("data:image/png;base64,") == 1 + n_generic
    assert len(re.findall(r"!\[[^\]]*\]\(report_files/[^)]+\.png\)", md_text)) == 1 + n_generic
    assert len(re.findall(r"!\[max_error vs source.n_points", md_text)) == n_generic
    assert md_text.index("study curve") < md_text.index("Runs")
    assert ("--generic-plots" in md_text) == (flag == [])  # the default says how to get them


def test_sweep_report_generic_default_without_study_figures(tmp_path, fake_loader):
    """No plugin has sweep figures: the generic plots are the report's figures by default."""
    ds = sweep_by_hand(make_sweep_dirs(tmp_path) or tmp_path)
    assert render_html(build_sweep_report(ds, tmp_path)).count("<img") == 1
    assert render_html(build_sweep_report(ds, tmp_path, generic=False)).count("<img") == 0


def test_cli_help_documents_generic_plots(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert "--generic-plots" in out and "--no-generic-plots" in out and "swept" in out


@pytest.mark.parametrize("setup, message", [
    (lambda p: p / "missing", "does not exist"),
    (lambda p: p, "No results.nc"),
])
def test_cli_errors(tmp_path, capsys, setup, message):
    assert main([str(setup(tmp_path))]) == 1
    err = capsys.readouterr().err.strip()
    assert message in err and "Traceback" not in err and len(err.splitlines()) == 1


def test_cli_bad_format(tmp_path, capsys):
    make_run(10).to_netcdf(tmp_path / "results.nc")
    assert main([str(tmp_path), "--format", "pdf"]) == 1
    assert "valid: html,md" in capsys.readouterr().err


def test_import_pointatlas_stays_light():
    code = "import sys, pointatlas, pointatlas.report, pointatlas.report_cli; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
