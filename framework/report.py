"""Reports of a run or a sweep: what was run, the metrics, the experiment's figures.

A :class:`Report` is a plain tree (sections of text, tables, preformatted blocks and PNG
images) built from a results Dataset (``results.nc``, see RESULTS_FORMAT) by
:func:`build_run_report` / :func:`build_sweep_report`, and written by :func:`write_report` as

- ``report.html``: self-contained (inline CSS, figures embedded as base64 PNG ``<img>``);
- ``report.md``: a Markdown twin whose figures are PNG files in ``report_files/``.

The report hard-codes no experiment. Figures come from the plugins named in
``attrs["plugins"]``: a plugin class may define ``report_figures(ds)`` (runs) and
``report_sweep_figures(ds)`` (sweeps) returning ``[(title, Figure | bytes)]`` where
``bytes`` is a ready PNG (e.g. a pyvista screenshot). The report adds generic figures only
for sweeps (each metric against each swept numeric parameter) and a table of runs.

Regenerating from the same results gives byte-identical files: no timestamps, sorted
iteration, fixed dpi, PNGs without ``Software`` metadata (see :mod:`pointatlas.report_figures`).
"""
from __future__ import annotations

import base64
import html
import json
import math
import os
import re
import tempfile
from pathlib import Path
from typing import Any

from .headline import headline_rows
from .report_blocks import Block, Details, Image, Pre, Report, Section, Table, Text  # noqa: F401
from .registry import load_plugin
from .report_figures import figure_to_png, metric_vs_param_figures, sweep_params, sweep_records

FILES_DIR = "report_files"
FORMATS = ("html", "md")

_PROVENANCE = ("source", "git_commit", "hostname", "history", "seed", "start_time", "end_time",
               "wall_time_s", "status", "run_id", "pointatlas_schema", "Conventions")


# --------------------------------------------------------------------------- formatting


def format_value(value: Any) -> str:
    """Short, stable text for a metric or attribute value."""
    if hasattr(value, "item") and getattr(value, "ndim", 0) == 0:
        value = value.item()
    if isinstance(value, bytes):
        value = value.decode("utf-8", "replace")
    if isinstance(value, bool) or value is None:
        return str(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return "nan" if math.isnan(value) else f"{value:.6g}"
    return str(value)


def _json(ds, key: str, default: Any) -> Any:
    raw = ds.attrs.get(key)
    if raw in (None, ""):
        return default
    try:
        return json.loads(raw)
    except (TypeError, ValueError):
        return default


# --------------------------------------------------------------------------- sections


def what_was_run(ds, directory: Path | None, kind: str) -> list[Section]:
    """Experiment, plugins and overrides; provenance; the resolved config collapsed."""
    a = ds.attrs
    rows = [("experiment", a.get("experiment", "")), ("study", a.get("study", ""))]
    if directory is not None:
        rows.insert(0, (f"{kind} directory", Path(directory).name))
    for family, name in sorted(_json(ds, "plugins", {}).items()):
        rows.append((f"plugin: {family}", name))
    overrides = _json(ds, "overrides", [])
    first = " (first run)" if kind == "sweep" else ""
    rows.append((f"overrides{first}", " ".join(str(o) for o in overrides) or "(none)"))
    sections = [Section("What was run", [Table(("item", "value"),
                                               tuple((k, format_value(v)) for k, v in rows))])]
    prov = tuple((k, format_value(a[k])) for k in _PROVENANCE if k in a)
    sections.append(Section(f"Provenance{first}", [Table(("attribute", "value"), prov)]))
    if a.get("config"):
        sections.append(Section(f"Configuration{first}", [Details(
            "resolved configuration (YAML)", str(a["config"]).rstrip("\n"))]))
    return sections


def headline_section(ds) -> Section | None:
    """The run's result first: its headline metrics against their references."""
    headers, rows = headline_rows(ds)
    if not rows:
        return None
    failed = sum(r[6] == "FAIL" for r in rows)
    judged = sum(r[6] in ("pass", "FAIL") for r in rows)
    summary = (f"{judged - failed} of {judged} within the experiment's tolerance."
               if judged else "No tolerance stated by the experiment.")
    return Section("Result", [Table(headers, rows), Text(summary)])


def metrics_table(ds) -> Table | None:
    """0-d variables: metric order of ``attrs["metrics"]`` first, then the rest by name."""
    scalars = sorted(str(n) for n, v in ds.data_vars.items() if v.ndim == 0)
    listed = [n for n in _json(ds, "metrics", []) if n in scalars]
    names = listed + [n for n in scalars if n not in listed]
    if not names:
        return None
    with_ref = any("reference" in ds[n].attrs for n in names)
    headers = ["metric", "long_name", "units", "value"]
    if with_ref:
        headers += ["reference", "relative difference", "reference source"]
    rows = []
    for n in names:
        var = ds[n]
        row = [n, str(var.attrs.get("long_name", "")), str(var.attrs.get("units", "")),
               format_value(var.values)]
        if with_ref:
            row += _reference_cells(var.values, var.attrs)
        rows.append(tuple(row))
    return Table(tuple(headers), tuple(rows))


def _reference_cells(value: Any, attrs: dict) -> list[str]:
    if "reference" not in attrs:
        return ["", "", ""]
    ref = attrs["reference"]
    try:
        v, r = float(value), float(ref)
        rel = format_value((v - r) / abs(r)) if r != 0 and math.isfinite(r) else "n/a"
    except (TypeError, ValueError):
        rel = "n/a"
    return [format_value(ref), rel, str(attrs.get("reference_source", ""))]


def data_overview(ds) -> Table | None:
    """Array variables (non 0-d): dims, shape, long_name, units."""
    rows = tuple(
        (str(n), ", ".join(f"{d}={ds.sizes[d]}" for d in v.dims),
         str(v.attrs.get("long_name", "")), str(v.attrs.get("units", "")))
        for n, v in sorted(ds.data_vars.items(), key=lambda kv: str(kv[0])) if v.ndim > 0
    )
    return Table(("variable", "dims", "long_name", "units"), rows) if rows else None


def plugin_figures(ds, hook: str) -> list[Block]:
    """Call ``hook`` ('report_figures' / 'report_sweep_figures') on each plugin of the run.

    A plugin that cannot be loaded, or whose hook fails or returns something unusable, gives a
    note instead of figures; the report is still written.
    """
    blocks: list[Block] = []
    for family, name in sorted(_json(ds, "plugins", {}).items()):
        try:
            cls = load_plugin(family, name)
        except Exception as exc:  # noqa: BLE001 - a missing plugin must not stop the report
            blocks.append(Text(f"Figures of {family} plugin {name!r} skipped: {exc}"))
            continue
        make = getattr(cls, hook, None)
        if make is None:
            continue
        try:
            produced = list(make(ds))
        except Exception as exc:  # noqa: BLE001
            blocks.append(Text(f"{family} plugin {name!r}: {hook} failed: {type(exc).__name__}: {exc}"))
            continue
        for item in produced:
            try:
                title, figure = item
                blocks.append(Image(f"{family} {name}: {title}", figure_to_png(figure)))
            except Exception as exc:  # noqa: BLE001
                blocks.append(Text(f"{family} plugin {name!r}: a figure was skipped: {exc}"))
    return blocks


# --------------------------------------------------------------------------- builders


def build_run_report(ds, run_dir: str | os.PathLike | None = None) -> Report:
    """Report of one run from its results Dataset (``run_dir`` only names the run): the
    result, the study's figures, all metrics, the data, then what was run and provenance."""
    title = str(ds.attrs.get("title") or f"pointatlas run {ds.attrs.get('run_id', '')}".strip())
    report = Report(title)
    headline = headline_section(ds)
    if headline:
        report.sections.append(headline)
    figures = plugin_figures(ds, "report_figures")
    report.sections.append(Section("Figures", figures or [Text("No plugin supplied figures.")]))
    table = metrics_table(ds)
    report.sections.append(Section("Metrics", [table] if table else [Text("No scalar metrics.")]))
    overview = data_overview(ds)
    if overview:
        report.sections.append(Section("Data", [overview]))
    report.sections += what_was_run(ds, Path(run_dir) if run_dir else None, "run")
    return report


def build_sweep_report(ds, sweep_dir: str | os.PathLike | None = None,
                       generic: bool | None = None) -> Report:
    """Report of a sweep from :func:`pointatlas.open_sweep`'s Dataset: the study's sweep
    figures first, the runs, then (``generic``) each metric that varies against each swept
    numeric parameter, then what was run.

    ``generic=None`` (the default) adds those generic plots only when no plugin supplied a
    sweep figure of its own, and otherwise says how to get them (``pointatlas-report
    --generic-plots``); ``True`` / ``False`` always / never add them."""
    title = str(ds.attrs.get("title") or "pointatlas sweep")
    report = Report(f"Sweep: {title}")
    params = sweep_params(ds)
    records = sweep_records(ds)
    intro = Text(f"{len(records)} runs; swept parameters: {', '.join(params) or '(none)'}.")
    figures = plugin_figures(ds, "report_sweep_figures")
    hint: list[Block] = []
    if generic is None:
        generic = not any(isinstance(block, Image) for block in figures)
        if not generic:
            hint = [Text("Generic plots (each metric that varies against each swept parameter) "
                         "are left out because the plugins supplied their own sweep figures; "
                         "add them with: pointatlas-report --generic-plots")]
    report.sections.append(Section("Figures", [intro, *figures, *hint]))
    report.sections.append(Section("Runs", [_records_table(records)] if records else [Text("No runs.")]))
    table = metrics_table(ds)
    if table:
        report.sections.append(Section("Sweep-wide metrics", [table]))
    if generic:
        plots = [Image(t, figure_to_png(f)) for t, f in metric_vs_param_figures(ds)]
        report.sections.append(Section("Metrics against swept parameters", plots or [
            Text("No metric varies with a numeric swept parameter.")]))
    report.sections += what_was_run(ds, Path(sweep_dir) if sweep_dir else None, "sweep")
    return report


def _records_table(records: list[dict]) -> Table:
    headers: list[str] = []
    for r in records:
        headers += [k for k in r if k not in headers]
    rows = tuple(tuple(format_value(r.get(h, "")) for h in headers) for r in records)
    return Table(tuple(headers), rows)


# --------------------------------------------------------------------------- rendering

_CSS = """body{font-family:system-ui,sans-serif;max-width:60em;margin:2em auto;padding:0 1em;color:#222;
overflow-wrap:break-word}
.wide{max-width:100%;overflow-x:auto}
table{border-collapse:collapse;margin:0.5em 0;font-size:0.9em}
th,td{border:1px solid #ccc;padding:0.2em 0.6em;text-align:left;vertical-align:top;
overflow-wrap:break-word;max-width:28em}th{white-space:nowrap}
th{background:#f2f2f2}pre{background:#f7f7f7;padding:0.6em;overflow-x:auto}
details{margin:0.5em 0}summary{cursor:pointer}
figure{margin:1em 0}figcaption{font-style:italic}img{max-width:100%;height:auto}"""


def render_html(report: Report) -> str:
    """Self-contained HTML: inline CSS, images as base64 data URIs, no external resources."""
    e = html.escape
    out = ["<!DOCTYPE html>", '<html lang="en">', "<head>", '<meta charset="utf-8">',
           f"<title>{e(report.title)}</title>", f"<style>\n{_CSS}\n</style>", "</head>", "<body>",
           f"<h1>{e(report.title)}</h1>"]
    for section in report.sections:
        out.append(f"<h2>{e(section.heading)}</h2>")
        for b in section.blocks:
            if isinstance(b, Text):
                out.append(f"<p>{e(b.text)}</p>")
            elif isinstance(b, Pre):
                out.append(f"<pre>{e(b.text)}</pre>")
            elif isinstance(b, Details):
                out.append(f"<details><summary>{e(b.summary)}</summary><pre>{e(b.text)}</pre>"
                           "</details>")
            elif isinstance(b, Table):
                out.append('<div class="wide"><table>')
                out.append("<tr>" + "".join(f"<th>{e(h)}</th>" for h in b.headers) + "</tr>")
                for row in b.rows:
                    out.append("<tr>" + "".join(f"<td>{e(c)}</td>" for c in row) + "</tr>")
                out.append("</table></div>")
            elif isinstance(b, Image):
                data = base64.b64encode(b.png).decode("ascii")
                out.append(f'<figure><img src="data:image/png;base64,{data}" alt="{e(b.title)}">'
                           f"<figcaption>{e(b.title)}</figcaption></figure>")
    out += ["</body>", "</html>", ""]
    return "\n".join(out)


def _slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")[:60] or "figure"


def image_filenames(report: Report) -> list[str]:
    """File names of the report's images in ``report_files/`` (numbered, in report order)."""
    return [f"fig-{i:02d}-{_slug(img.title)}.png" for i, img in enumerate(report.images(), 1)]


def _md_cell(text: str) -> str:
    return _md_text(text).replace("|", "\\|").replace("\n", " ")


def _md_text(text: str) -> str:
    """User text made literal in Markdown: emphasis, code, link and HTML characters
    escaped (intraword ``_`` is literal in GitHub Markdown and left readable)."""
    text = re.sub(r"([\\`*\[\]<>])", r"\\\1", str(text))
    return text


def render_markdown(report: Report, files_dir: str = FILES_DIR) -> tuple[str, dict[str, bytes]]:
    """Markdown text and ``{file name: PNG bytes}`` for the images it links in ``files_dir``."""
    names = iter(image_filenames(report))
    files: dict[str, bytes] = {}
    out = [f"# {_md_text(report.title)}", ""]
    for section in report.sections:
        out += [f"## {_md_text(section.heading)}", ""]
        for b in section.blocks:
            if isinstance(b, Text):
                out += [_md_text(b.text), ""]
            elif isinstance(b, Pre):
                fence = "~~~~" if "```" in b.text else "```"
                out += [fence, b.text, fence, ""]
            elif isinstance(b, Details):
                fence = "~~~~" if "```" in b.text else "```"
                out += ["<details>", f"<summary>{html.escape(b.summary)}</summary>", "",
                        fence, b.text, fence, "", "</details>", ""]
            elif isinstance(b, Table):
                out.append("| " + " | ".join(_md_cell(h) for h in b.headers) + " |")
                out.append("|" + "---|" * len(b.headers))
                out += ["| " + " | ".join(_md_cell(c) for c in row) + " |" for row in b.rows]
                out.append("")
            elif isinstance(b, Image):
                name = next(names)
                files[name] = b.png
                alt = b.title.replace("[", "(").replace("]", ")")
                out += [f"![{alt}]({files_dir}/{name})", "", f"*{_md_text(b.title)}*", ""]
    return "\n".join(out), files


# --------------------------------------------------------------------------- writing


def atomic_write(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder and os.replace."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def write_report(report: Report, out_dir: str | os.PathLike,
                 formats: tuple[str, ...] = FORMATS, stem: str = "report") -> list[Path]:
    """Write ``<stem>.html`` and/or ``<stem>.md`` (+ ``report_files/``) into ``out_dir``.

    Stale ``fig-*.png`` files in ``report_files/`` from an earlier report are removed.
    Returns the written report paths.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    if "html" in formats:
        atomic_write(out / f"{stem}.html", render_html(report).encode("utf-8"))
        written.append(out / f"{stem}.html")
    if "md" in formats:
        text, files = render_markdown(report, FILES_DIR)
        folder = out / FILES_DIR
        if files:
            folder.mkdir(exist_ok=True)
        for name, png in sorted(files.items()):
            atomic_write(folder / name, png)
        if folder.is_dir():
            for old in folder.glob("fig-*.png"):
                if old.name not in files:
                    old.unlink()
        atomic_write(out / f"{stem}.md", text.encode("utf-8"))
        written.append(out / f"{stem}.md")
    return written
