"""``pointatlas-runs``: list, show and compare the runs recorded in the run catalog.

Subcommands::

    pointatlas-runs list [--root DIR] [--experiment X] [--status S] [--where key=value ...]
                         [--metric 'name<value' ...] [--format table|json] [--limit N]
    pointatlas-runs show ID [--format table|json]
    pointatlas-runs compare ID ID [...] [--format table|json]
    pointatlas-runs repair            rebuild the catalog from the run directories
    pointatlas-runs gc                remove the temporary files killed writes left behind

A run recorded as running whose process is gone (killed, out of memory, a lost node) is
listed as ``died``.

The outputs root is ``--root``, else the environment variable ``POINTATLAS_OUTPUTS``, else
``./outputs``; the catalog is ``<root>/catalog.sqlite``. Errors print one line to stderr and
exit non-zero; ``--format json`` prints only JSON on stdout. Standard library only.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sqlite3
import sys
from dataclasses import asdict
from pathlib import Path
from typing import Sequence

from .catalog import (DIED, METRIC_SYNTAX, MISSING, STATUSES, WHERE_SYNTAX, Catalog, RunRecord,
                      catalog_path)
from .errors import PointatlasError

PROG = "pointatlas-runs"
ENV_ROOT = "POINTATLAS_OUTPUTS"
_SHORT_ID = 8
_CELL_MAX = 60


class _UsageError(Exception):
    """A command-line usage error (exit code 2)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # one line, no usage dump
        raise _UsageError(f"{message} (see {self.prog} --help)")


def build_parser() -> argparse.ArgumentParser:
    """The ``pointatlas-runs`` argument parser."""
    parser = _Parser(prog=PROG, description="List, show and compare pointatlas runs.")
    parser.add_argument("--root", default=None, help=f"outputs root (default: ${ENV_ROOT} or ./outputs)")
    common = _Parser(add_help=False)
    common.add_argument("--root", default=argparse.SUPPRESS,
                        help=f"outputs root holding catalog.sqlite (default: ${ENV_ROOT} or ./outputs)")
    common.add_argument("--format", choices=("table", "json"), default="table", help="output format")
    sub = parser.add_subparsers(dest="command", metavar="{list,show,compare,repair,gc}",
                                parser_class=_Parser)
    sub.required = True

    listing = sub.add_parser("list", parents=[common], help="list runs (oldest first)")
    listing.add_argument("--experiment", help="only runs of this experiment")
    listing.add_argument("--status", choices=(*STATUSES, MISSING, DIED),
                         help="only runs with this status")
    listing.add_argument("--where", action="append", default=[], metavar="KEY=VALUE",
                         help=f"override/param filter, repeatable: {WHERE_SYNTAX}")
    listing.add_argument("--metric", action="append", default=[], metavar="EXPR",
                         help=f"metric threshold, repeatable: {METRIC_SYNTAX}")
    listing.add_argument("--limit", type=_non_negative, default=None, metavar="N",
                         help="show only the N most recent matching runs")

    show = sub.add_parser("show", parents=[common], help="every field of one run")
    show.add_argument("run_id", metavar="ID", help="run id or unique prefix")

    compare = sub.add_parser("compare", parents=[common], help="runs side by side")
    compare.add_argument("run_ids", metavar="ID", nargs="+", help="two or more run ids or prefixes")
    sub.add_parser("repair", parents=[common], help="move a damaged catalog aside and rebuild "
                   "it from the results.nc / run.json files under the root")
    sub.add_parser("gc", parents=[common], help="remove the temporary files (.results.nc.*.tmp, "
                   "*.partial.nc) that killed writes left in run directories")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``pointatlas-runs``; returns the exit code (0 ok, 1 error, 2 usage)."""
    try:
        try:
            args = build_parser().parse_args(argv)
        except SystemExit as exc:  # --help
            return int(exc.code or 0)
        if args.command == "compare" and len(args.run_ids) < 2:
            raise _UsageError("compare needs at least two run ids")
        if args.command in ("repair", "gc"):
            output = _cmd_repair(args) if args.command == "repair" else _cmd_gc(args)
        else:
            catalog = _open_catalog(_root(args.root))
            output = {"list": _cmd_list, "show": _cmd_show,
                      "compare": _cmd_compare}[args.command](catalog, args)
        sys.stdout.write(output if output.endswith("\n") else output + "\n")
        sys.stdout.flush()
        return 0
    except _UsageError as exc:
        _fail(f"error: {exc}")
        return 2
    except PointatlasError as exc:
        _fail(str(exc))
        return 1
    except sqlite3.Error as exc:
        _fail(f"cannot read the catalog {catalog_path(_root(getattr(args, 'root', None)))}: {exc}. "
              f"Fix: `{PROG} repair` rebuilds it from the run directories.")
        return 1
    except BrokenPipeError:
        _silence_stdout()
        return 0
    except OSError as exc:
        _fail(f"error: {exc}")
        return 1
    except KeyboardInterrupt:
        _fail("interrupted")
        return 130


def _fail(message: str) -> None:
    print(f"{PROG}: {' '.join(str(message).split())}", file=sys.stderr)


def _silence_stdout() -> None:
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass


def _non_negative(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"{value} is negative: use N >= 0")
    return value


def _root(option: str | None) -> Path:
    return Path(option or os.environ.get(ENV_ROOT) or "outputs")


def _open_catalog(root: Path) -> Catalog:
    path = catalog_path(root)
    if not path.is_file():
        raise PointatlasError(f"no catalog at {path}: run `pointatlas` first or pass --root")
    return Catalog(path)


# ----------------------------------------------------------------------------- commands


def _cmd_list(catalog: Catalog, args: argparse.Namespace) -> str:
    records = catalog.runs(experiment=args.experiment, status=args.status, where=args.where,
                           metric=args.metric, limit=args.limit)
    if args.format == "json":
        return _json([_record_json(r) for r in records])
    if not records:
        return "no runs match"
    short = short_ids(catalog.ids())
    header = ["id", "experiment", "status", "start", "wall time", "overrides", "metrics"]
    rows = [[short.get(r.id, r.id), r.experiment, r.status, _time(r.start_time),
             _duration(r.wall_time_s), _clip(" ".join(r.overrides)), _clip(_metrics_cell(r.metrics))]
            for r in records]
    return _table(header, rows)


def _cmd_show(catalog: Catalog, args: argparse.Namespace) -> str:
    record = catalog.get(args.run_id)
    if args.format == "json":
        return _json(_record_json(record))
    lines = [
        ("id", record.id), ("experiment", record.experiment),
        ("status", record.status if record.status == record.recorded_status
         else f"{record.status} (recorded: {record.recorded_status})"),
        ("start", record.start_time or "-"), ("end", record.end_time or "-"),
        ("wall time", _duration(record.wall_time_s)), ("path", record.path or "-"),
        ("git commit", record.git_commit or "-"), ("error", record.error or "-"),
        ("process", f"{record.pid} on {record.host}" if record.pid else "-"),
        ("heartbeat", record.heartbeat or "-"),
    ]
    width = max(len(k) for k, _ in lines)
    out = [f"{k:<{width}}  {v}" for k, v in lines]
    out.append("overrides:" + ("" if record.overrides else " -"))
    out += [f"  {item}" for item in record.overrides]
    out.append("params:" + ("" if record.params else " -"))
    out += [f"  {k} = {v}" for k, v in sorted(record.params.items())]
    out.append("metrics:" + ("" if record.metrics else " -"))
    if record.metrics:
        name_width = max(len(n) for n in record.metrics)
        out += [f"  {n:<{name_width}}  {_number(v)}" for n, v in sorted(record.metrics.items())]
    return "\n".join(out)


def _cmd_compare(catalog: Catalog, args: argparse.Namespace) -> str:
    records = [catalog.get(run_id) for run_id in args.run_ids]
    settings = [r.settings() for r in records]
    keys = sorted({k for s in settings for k in s})
    differing = {k: [s.get(k) for s in settings] for k in keys
                 if len({s.get(k) for s in settings}) > 1}
    names = sorted({n for r in records for n in r.metrics})
    metrics = {n: [r.metrics.get(n) for r in records] for n in names}
    if args.format == "json":
        return _json({
            "runs": [r.id for r in records],
            "experiment": [r.experiment for r in records],
            "status": [r.status for r in records],
            "wall_time_s": [_finite(r.wall_time_s) for r in records],
            "git_commit": [r.git_commit for r in records],
            "differing": differing,
            "metrics": {n: [_finite(v) for v in values] for n, values in metrics.items()},
        })
    short = short_ids(catalog.ids())
    header = [""] + [short.get(r.id, r.id) for r in records]
    rows = [["experiment"] + [r.experiment for r in records],
            ["status"] + [r.status for r in records],
            ["start"] + [_time(r.start_time) for r in records],
            ["wall time"] + [_duration(r.wall_time_s) for r in records]]
    if len({r.git_commit for r in records}) > 1:
        rows.append(["git commit"] + [r.git_commit[:10] or "-" for r in records])
    sections = [_table(header, rows)]
    sections.append(_table(["differing setting"] + header[1:],
                           [[k] + [_clip("-" if v is None else v) for v in vals]
                            for k, vals in differing.items()])
                    if differing else "differing settings: none")
    sections.append(_table(["metric"] + header[1:],
                           [[n] + ["-" if v is None else _number(v) for v in vals]
                            for n, vals in metrics.items()])
                    if metrics else "metrics: none")
    return "\n\n".join(sections)


def _existing_root(args: argparse.Namespace) -> Path:
    root = _root(args.root)
    if not root.is_dir():
        raise PointatlasError(f"no outputs root at {root}: pass --root <the outputs_root of your runs>")
    return root


def _cmd_repair(args: argparse.Namespace) -> str:
    from .catalog_repair import rebuild_catalog

    root = _existing_root(args)
    report = rebuild_catalog(root)
    if args.format == "json":
        return _json({"catalog": str(catalog_path(root)), "moved_aside": list(map(str, report.moved_aside)),
                      "completed": report.completed, "failed": report.failed,
                      "unfinished": report.unfinished,
                      "unreadable": list(map(str, report.unreadable))})
    return report.text(catalog_path(root))


def _cmd_gc(args: argparse.Namespace) -> str:
    from .catalog_repair import collect_garbage

    root = _existing_root(args)
    removed = collect_garbage(root)
    if args.format == "json":
        return _json({"removed": list(map(str, removed))})
    return f"removed {len(removed)} leftover temporary files under {root}" + "".join(
        f"\n  {p}" for p in removed)


# ----------------------------------------------------------------------------- formatting


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


def _table(header: list[str], rows: list[list[str]]) -> str:
    widths = [max(len(str(row[i])) for row in [header, *rows]) for i in range(len(header))]
    lines = ["  ".join(str(cell).ljust(w) for cell, w in zip(row, widths)).rstrip()
             for row in [header, [("-" * w) for w in widths], *rows]]
    return "\n".join(lines)


def _clip(text: str, limit: int = _CELL_MAX) -> str:
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _metrics_cell(metrics: dict[str, float]) -> str:
    return " ".join(f"{name}={_number(value)}" for name, value in metrics.items())


def _number(value: float | None) -> str:
    return "-" if value is None else f"{value:.4g}"


def _time(iso: str | None) -> str:
    if not iso:
        return "-"
    text = iso.replace("T", " ")
    return text[:19]


def _duration(seconds: float | None) -> str:
    if seconds is None or not math.isfinite(seconds):
        return "-"
    if seconds < 60:
        return f"{seconds:.1f} s"
    minutes, secs = divmod(int(round(seconds)), 60)
    if minutes < 60:
        return f"{minutes}m {secs:02d}s"
    hours, minutes = divmod(minutes, 60)
    return f"{hours}h {minutes:02d}m"


def _finite(value: float | None) -> float | None:
    return value if value is not None and math.isfinite(value) else None


def _record_json(record: RunRecord) -> dict:
    data = asdict(record)
    data["wall_time_s"] = _finite(record.wall_time_s)
    data["metrics"] = {n: _finite(v) for n, v in record.metrics.items()}
    return data


def _json(data) -> str:
    """Strict JSON (non-finite numbers are written as null)."""
    return json.dumps(data, indent=2, allow_nan=False)


if __name__ == "__main__":
    sys.exit(main())
