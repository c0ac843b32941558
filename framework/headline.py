"""The headline of a run: the few metrics a study is about, against their references.

A study declares them as a class attribute ``headline_metrics = ("displacement", ...)``; a
study that declares none has as headline every scalar metric carrying a ``reference`` attr
(the published or exact value, with ``reference_source``). An experiment states how close is
close enough in ``extra.tolerances: {metric: relative tolerance}``, stored on the variable as
``tolerance``. The run writes the list in ``attrs["headline"]``; the report opens with
:func:`headline_rows`: value, reference, relative error |v − r| / |r| and pass/fail.
"""
from __future__ import annotations

import json
import math
from typing import Any

from .errors import ConfigError


def declare_headline(ds, study_class: type, config: dict) -> list[str]:
    """The headline metric names of ``ds`` (see the module doc); the experiment's
    tolerances are set on the variables. A tolerance for a metric the results do not have is
    refused (a misspelt name would otherwise pass silently)."""
    scalars = [str(n) for n, v in ds.data_vars.items() if v.ndim == 0]
    declared = list(getattr(study_class, "headline_metrics", ()) or ())
    names = [n for n in declared if n in scalars] or [
        n for n in scalars if "reference" in ds[n].attrs]
    tolerances = ((config.get("extra") or {}).get("tolerances") or {})
    for name, tol in tolerances.items():
        if name not in scalars:
            raise ConfigError(f"extra.tolerances names {name!r}, which is not a scalar metric "
                              f"of this run ({', '.join(scalars)}). Fix the metric name.")
        try:
            tol = float(tol)
        except (TypeError, ValueError):
            tol = math.nan
        if not tol > 0:
            raise ConfigError(f"extra.tolerances.{name}={tolerances[name]!r}: give a positive "
                              "relative tolerance.")
        ds[name].attrs["tolerance"] = tol
        if name not in names:
            names.append(name)
    return names


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return "nan" if math.isnan(value) else f"{value:.6g}"
    return str(value)


def verdict(value: float, reference: float | None, tolerance: float | None) -> tuple[str, str]:
    """(relative error text, verdict): "pass"/"FAIL" against the tolerance, "-" without."""
    if reference is None or not math.isfinite(reference):
        return "-", "-"
    if reference == 0:
        error = abs(value)
        text = f"{error:.3g} (absolute)"
    else:
        error = abs(value - reference) / abs(reference)
        text = f"{error:.3g}"
    if tolerance is None:
        return text, "-"
    return text, ("pass" if math.isfinite(error) and error <= tolerance else "FAIL")


def headline_rows(ds) -> tuple[tuple[str, ...], tuple[tuple[str, ...], ...]]:
    """Headers and rows of the headline table (empty rows: no headline)."""
    try:
        names = json.loads(ds.attrs.get("headline") or "[]")
    except (TypeError, ValueError):
        names = []
    headers = ("result", "value", "units", "reference", "relative error", "tolerance",
               "verdict", "reference source")
    rows = []
    for name in names:
        if name not in ds:
            continue
        var = ds[name]
        value = float(var.values)
        ref = var.attrs.get("reference")
        ref = float(ref) if ref is not None and _is_number(ref) else None
        tol = var.attrs.get("tolerance")
        tol = float(tol) if tol is not None and _is_number(tol) else None
        error, mark = verdict(value, ref, tol)
        rows.append((str(var.attrs.get("long_name") or name), _fmt(value),
                     str(var.attrs.get("units", "")), "-" if ref is None else _fmt(ref), error,
                     "-" if tol is None else f"{tol:.3g}", mark,
                     str(var.attrs.get("reference_source", ""))))
    return headers, tuple(rows)


def _is_number(value: Any) -> bool:
    try:
        float(value)
        return True
    except (TypeError, ValueError):
        return False


__all__ = ["declare_headline", "headline_rows", "verdict"]
