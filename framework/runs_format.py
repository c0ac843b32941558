"""Text and JSON formatting of catalog records for ``pointatlas-runs``: tables, shortest
unique id prefixes, durations, and numbers with enough significant figures to tell runs
apart. Standard library only."""
from __future__ import annotations

import json
import math
import os
from dataclasses import asdict
from typing import Iterable, Sequence

from .catalog_rows import RunRecord

_SHORT_ID = 8
_CELL_MAX = 60


def short_ids(ids: Sequence[str], minimum: int = _SHORT_ID) -> dict[str, str]:
    """Shortest prefix (at least ``minimum`` characters) that identifies each id uniquely."""
    ordered = sorted(set(ids))
    result = {}
    for i, run_id in enumerate(ordered):
        common = 0
        for neighbour in ordered[max(i - 1, 0):i] + ordered[i + 1:i + 2]:
            common = max(common, len(os.path.commonprefix([run_id, neighbour])))
        result[run_id] = run_id[:max(minimum, common + 1)]
    return result


def table(header: list[str], rows: list[list[str]]) -> str:
    widths = [max(len(str(row[i])) for row in [header, *rows]) for i in range(len(header))]
    lines = ["  ".join(str(cell).ljust(w) for cell, w in zip(row, widths)).rstrip()
             for row in [header, [("-" * w) for w in widths], *rows]]
    return "\n".join(lines)


def clip(text: str, limit: int = _CELL_MAX) -> str:
    return text if len(text) <= limit else text[:limit - 3] + "..."


def metrics_cell(metrics: dict[str, float], digits: dict[str, int]) -> str:
    return " ".join(f"{name}={number(value, digits.get(name, 4))}"
                    for name, value in metrics.items())


def number(value: float | None, digits: int = 4) -> str:
    """``value`` to ``digits`` significant figures ("-" when absent)."""
    return "-" if value is None else f"{value:.{digits}g}"


def distinct_digits(values: Iterable[float | None], minimum: int = 4) -> int:
    """The fewest significant figures (at least ``minimum``, at most 17) at which values
    that differ print differently (1.2266, 1.2261 rather than 1.227, 1.226)."""
    finite = sorted({float(v) for v in values if v is not None and math.isfinite(v)})
    for digits in range(minimum, 18):
        if len({number(v, digits) for v in finite}) == len(finite):
            return digits
    return 17


def metric_digits(records: Sequence[RunRecord], digits: int | None) -> dict[str, int]:
    """Significant figures per metric name: ``digits`` if given, else enough to tell the
    runs' values apart (:func:`distinct_digits`)."""
    names = {n for r in records for n in r.metrics}
    return {n: digits or distinct_digits(r.metrics.get(n) for r in records) for n in names}


def short_time(iso: str | None) -> str:
    if not iso:
        return "-"
    text = iso.replace("T", " ")
    return text[:19]


def duration(seconds: float | None) -> str:
    if seconds is None or not math.isfinite(seconds):
        return "-"
    if seconds < 60:
        return f"{seconds:.1f} s"
    minutes, secs = divmod(int(round(seconds)), 60)
    if minutes < 60:
        return f"{minutes}m {secs:02d}s"
    hours, minutes = divmod(minutes, 60)
    return f"{hours}h {minutes:02d}m"


def finite(value: float | None) -> float | None:
    return value if value is not None and math.isfinite(value) else None


def record_json(record: RunRecord) -> dict:
    data = asdict(record)
    data["wall_time_s"] = finite(record.wall_time_s)
    data["metrics"] = {n: finite(v) for n, v in record.metrics.items()}
    return data


def to_json(data) -> str:
    """Strict JSON (non-finite numbers are written as null)."""
    return json.dumps(data, indent=2, allow_nan=False)
