"""Figures the report draws itself, and the conversion of any figure to PNG bytes.

Plugins supply experiment-specific figures through ``report_figures(ds)`` /
``report_sweep_figures(ds)``; this module only holds what is generic to every results file:

- :func:`figure_to_png` turns a matplotlib Figure (or ready PNG bytes, e.g. a pyvista
  screenshot) into deterministic PNG bytes: Agg renderer, fixed dpi, no ``Software``
  metadata (matplotlib's PNG writer then stores no timestamp), figure closed afterwards.
- :func:`sweep_records` flattens a sweep Dataset (grid dims or a ``run`` dim) into rows.
- :func:`metric_vs_param_figures` plots each metric against each swept numeric parameter.

matplotlib is imported inside functions only, so ``import pointatlas`` stays light.
"""
from __future__ import annotations

import json
import math
import sys
from typing import Any

#: Resolution of every PNG in a report (dots per inch). Fixed so that reports are reproducible.
DPI = 100
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def figure_to_png(figure: Any, dpi: int = DPI) -> bytes:
    """PNG bytes of ``figure`` (a matplotlib Figure, or PNG ``bytes`` passed through).

    The figure is closed after saving (also in pyplot's figure manager, if it is known there).
    Raises TypeError for anything else, ValueError for bytes that are not a PNG.
    """
    if isinstance(figure, (bytes, bytearray, memoryview)):
        data = bytes(figure)
        if not data.startswith(PNG_SIGNATURE):
            raise ValueError("bytes given as a figure are not a PNG image (bad signature)")
        return data
    from io import BytesIO

    from matplotlib.figure import Figure

    if not isinstance(figure, Figure):
        raise TypeError(
            f"a report figure must be a matplotlib Figure or PNG bytes, not {type(figure).__name__}"
        )
    buffer = BytesIO()
    try:
        # format="png" renders with Agg whatever the interactive backend is.
        figure.savefig(buffer, format="png", dpi=dpi, metadata={"Software": None})
    finally:
        pyplot = sys.modules.get("matplotlib.pyplot")
        if pyplot is not None:
            pyplot.close(figure)
    return buffer.getvalue()


def sweep_params(ds) -> list[str]:
    """Swept override keys: ``attrs["sweep_params"]`` (JSON list), else the dims of the metrics."""
    raw = ds.attrs.get("sweep_params")
    if raw:
        return [str(p) for p in json.loads(raw)]
    dims: list[str] = []
    for name in sweep_metrics(ds):
        for dim in ds[name].dims:
            if dim not in dims:
                dims.append(str(dim))
    return dims


def sweep_metrics(ds) -> list[str]:
    """Names of the metric variables of a sweep (``attrs["metrics"]`` that exist in ``ds``)."""
    names = json.loads(ds.attrs.get("metrics", "[]") or "[]")
    return [str(n) for n in names if n in ds.data_vars]


def _python(value: Any) -> Any:
    """numpy scalar -> plain Python value (so rows print and compare simply)."""
    return value.item() if hasattr(value, "item") else value


def sweep_records(ds, extra: tuple[str, ...] = ("run_dir", "run_id", "status", "wall_time_s")) -> list[dict]:
    """One dict per run: swept parameters, then metrics, then any of ``extra`` present.

    Works for a full grid (parameters are dims) and for a ``run`` dim (parameters are coords).
    Rows come in the Dataset's own order (sorted grid coordinates, or run order).
    """
    params = sweep_params(ds)
    metrics = sweep_metrics(ds)
    wanted = [n for n in (*params, *metrics, *extra) if n in ds.variables]
    run_dims = [d for d in ds.dims if d in params or d == "run"]
    if not run_dims:
        return []
    import numpy as np

    shape = [ds.sizes[d] for d in run_dims]
    rows = []
    for index in np.ndindex(*shape):
        where = dict(zip(run_dims, index))
        row = {}
        for name in wanted:
            var = ds[name]
            sel = {d: i for d, i in where.items() if d in var.dims}
            if set(var.dims) - set(sel):  # not a per-run value
                continue
            row[name] = _python(var.isel(sel).values)
        rows.append(row)
    return rows


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def metric_vs_param_figures(ds) -> list[tuple[str, Any]]:
    """For each metric that varies and each swept numeric parameter: metric against
    parameter (not a metric that repeats the parameter, not constants, not timings).

    The other swept parameters split the points into one line each (legend ``k=v, ...``).
    Axes are log-log when every plotted value is positive, linear otherwise.
    Returns ``[(title, Figure)]``; NaN values (failed runs) are left out.
    """
    from matplotlib.figure import Figure

    records = sweep_records(ds)
    params = [p for p in sweep_params(ds) if any(p in r for r in records)]
    numeric = [p for p in params if all(_is_number(r.get(p)) for r in records)]
    figures = []
    for metric in sweep_metrics(ds):
        ys = [r.get(metric) for r in records if _is_number(r.get(metric))]
        if len({y for y in ys if not math.isnan(y)}) < 2 or metric.startswith("time_"):
            continue  # a constant says nothing against the sweep; timings have their own table
        attrs = ds[metric].attrs
        ylabel = _axis_label(metric, attrs)
        for param in numeric:
            if [r.get(param) for r in records] == [r.get(metric) for r in records]:
                continue  # the swept value itself (n_points against source_n_points)
            others = [p for p in params if p != param]
            lines: dict[tuple, list[tuple[float, float]]] = {}
            for r in records:
                x, y = r.get(param), r.get(metric)
                if not (_is_number(x) and _is_number(y)) or math.isnan(y) or math.isnan(x):
                    continue
                key = tuple((p, r.get(p)) for p in others)
                lines.setdefault(key, []).append((float(x), float(y)))
            if not lines:
                continue
            fig = Figure(figsize=(5.0, 3.6), layout="constrained")
            ax = fig.add_subplot()
            values = [v for pts in lines.values() for xy in pts for v in xy]
            for key in sorted(lines, key=repr):
                pts = sorted(lines[key])
                label = ", ".join(f"{p}={v}" for p, v in key) or None
                ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", label=label)
            if values and all(v > 0 for v in values):
                ax.set_xscale("log")
                ax.set_yscale("log")
            ax.set_xlabel(_axis_label(param, ds[param].attrs if param in ds.variables else {}))
            ax.set_ylabel(ylabel)
            ax.grid(True, which="both", alpha=0.3)
            if len(lines) > 1:
                ax.legend(fontsize="small")
            figures.append((f"{metric} vs {param}", fig))
    return figures


def _axis_label(name: str, attrs: dict) -> str:
    text = str(attrs.get("long_name", name))
    units = str(attrs.get("units", ""))
    return f"{text} [{units}]" if units and units != "1" else text
