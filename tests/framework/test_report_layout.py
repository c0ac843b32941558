"""Reports fit a 1 200-px-wide page: rendered by headless Chromium, nothing overflows, and the
run report leads with its result (the headline table before any figure or configuration)."""
import json
import re
import shutil
import subprocess

import numpy as np
import pytest
import xarray as xr

from pointatlas.headline import verdict
from pointatlas.report import build_run_report, build_sweep_report, write_report

CHROMIUM = next((shutil.which(n) for n in ("chromium-headless-shell", "chromium", "chromium-browser")
                 if shutil.which(n)), None)
needs_chromium = pytest.mark.skipif(CHROMIUM is None, reason="no headless Chromium (apt-get "
                                    "install chromium-headless-shell; .ci/run installs it)")
WIDTH = 1200


def _run(n_metrics=25, long=300) -> xr.Dataset:
    data = {f"metric_with_a_long_name_{i:02d}": ((), float(i) + 1 / 3, {
        "long_name": f"a quantity whose description goes on and on ({i})", "units": "m"})
        for i in range(n_metrics)}
    data["displacement"] = ((), 1.2259, {"long_name": "displacement", "units": "m",
                                         "reference": 1.2257, "tolerance": 0.005,
                                         "reference_source": "thesis"})
    data["field"] = (("point",), np.arange(5.0), {"long_name": "a field", "units": "m"})
    ds = xr.Dataset(data)
    ds.attrs.update({
        "title": "A run with a <b>title</b> & long settings " + "x" * 80,
        "experiment": "demo", "study": "shell", "run_id": "r1",
        "overrides": json.dumps([f"study.a_very_long_override_{i}={'y' * 40}" for i in range(8)]),
        "config": "\n".join(f"key_{i}: {'z' * long}" for i in range(40)),
        "plugins": json.dumps({}), "metrics": json.dumps(list(data)),
        "headline": json.dumps(["displacement"]), "history": "h " * 200,
        "source": "pointatlas " + "plugin=1.0; " * 40})
    return ds


def _sweep() -> xr.Dataset:
    runs = np.arange(12)
    data = {f"a_metric_with_a_long_name_{i}": (("run",), runs * 1.5 + i, {
        "long_name": f"metric {i}", "units": "1"}) for i in range(14)}
    ds = xr.Dataset(data, coords={"run": runs, "source_n_points": ("run", runs * 100 + 100)})
    ds.attrs.update({"title": "sweep", "metrics": json.dumps(list(data)),
                     "sweep_params": json.dumps(["source_n_points"]), "plugins": "{}",
                     "overrides": "[]", "config": "a: 1"})
    return ds


def _scroll_width(html_path, tmp_path) -> int:
    probe = tmp_path / "probe.html"
    probe.write_text(html_path.read_text().replace(
        "</body>", '<script>document.body.setAttribute("data-scroll-width", '
        "document.documentElement.scrollWidth)</script></body>"))
    out = subprocess.run([CHROMIUM, "--no-sandbox", "--headless", f"--window-size={WIDTH},900",
                          "--virtual-time-budget=2000", "--dump-dom", probe.as_uri()],
                         capture_output=True, text=True, timeout=120)
    found = re.search(r'data-scroll-width="(\d+)"', out.stdout)
    assert found, out.stderr[-2000:]
    return int(found.group(1))


def _screenshot(html_path, png_path) -> tuple[int, int]:
    subprocess.run([CHROMIUM, "--no-sandbox", "--headless", "--hide-scrollbars",
                    f"--screenshot={png_path}", f"--window-size={WIDTH},1600",
                    html_path.as_uri()], capture_output=True, timeout=120)
    import imageio.v3 as iio

    return iio.imread(png_path).shape[1::-1]


def test_the_run_report_leads_with_the_result(tmp_path):
    report = build_run_report(_run())
    headings = [s.heading for s in report.sections]
    assert headings[0] == "Result" and headings.index("Figures") < headings.index("What was run")
    assert headings[-1] == "Configuration"  # collapsed, at the end
    html_path, md_path = write_report(report, tmp_path)
    html_text = html_path.read_text()
    assert html_text.index("Result") < html_text.index("<details>")
    assert "<b>title</b>" not in html_text and "&lt;b&gt;title&lt;/b&gt;" in html_text
    assert "\\<b\\>title\\</b\\>" in md_path.read_text()
    assert verdict(1.2259, 1.2257, 0.005) == ("0.000163", "pass")
    assert verdict(1.3, 1.2257, 0.005)[1] == "FAIL" and verdict(1.0, None, 0.1) == ("-", "-")


@needs_chromium
@pytest.mark.parametrize("kind", ["run", "sweep"])
def test_reports_fit_a_1200_px_page(kind, tmp_path):
    report = build_run_report(_run()) if kind == "run" else build_sweep_report(_sweep())
    html_path = write_report(report, tmp_path, formats=("html",))[0]
    assert _scroll_width(html_path, tmp_path) <= WIDTH
    assert _screenshot(html_path, tmp_path / "shot.png") == (WIDTH, 1600)
