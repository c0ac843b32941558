"""``pointatlas-runs``: list, show and compare the runs recorded in the run catalog.

Subcommands::

    pointatlas-runs list [--root DIR] [--experiment X] [--status S] [--where key=value ...]
                         [--metric 'name<value' ...] [--format table|json] [--limit N]
    pointatlas-runs show ID [--format table|json]
    pointatlas-runs compare ID ID [...] [--format table|json]
    pointatlas-runs rm ID [...] [--keep-files]   remove runs (their directories too)
    pointatlas-runs rerun ID          run the same experiment with the same overrides again
    pointatlas-runs repair            rebuild the catalog from the run directories
    pointatlas-runs gc                remove the temporary files killed writes left behind

``list`` leaves out command lines rejected at start-up (``--status rejected`` or ``--all``
shows them). Filters and ``compare`` see each run's resolved settings (defaults included),
and ``--where n_points=441`` matches ``source.n_points``. Numbers get the significant figures
that tell the listed runs apart (at least 4), or ``--digits N``.

A run recorded as running whose process is gone (killed, out of memory, a lost node) is
listed as ``died``.

The outputs root is ``--root``, else the environment variable ``POINTATLAS_OUTPUTS``, else
``./outputs``; the catalog is ``<root>/catalog.sqlite``. Errors print one line to stderr and
exit non-zero; ``--format json`` prints only JSON on stdout. Standard library only.
"""
from __future__ import annotations

import argparse
import os
import sqlite3
import sys
from pathlib import Path
from typing import Sequence

from .catalog import DIED, METRIC_SYNTAX, MISSING, STATUSES, WHERE_SYNTAX, Catalog, catalog_path
from .errors import PointatlasError
from .runs_format import (clip, duration, finite, metric_digits, metrics_cell, number,
                          record_json, short_ids, short_time, table, to_json)

PROG = "pointatlas-runs"
ENV_ROOT = "POINTATLAS_OUTPUTS"


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
    common.add_argument("--digits", type=_positive, default=None, metavar="N",
                        help="significant figures of numbers (default: enough to tell runs apart)")
    sub = parser.add_subparsers(dest="command",
                                metavar="{list,show,compare,rm,rerun,repair,gc}",
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
    listing.add_argument("--all", action="store_true",
                         help="also the command lines rejected at start-up")

    show = sub.add_parser("show", parents=[common], help="every field of one run")
    show.add_argument("run_id", metavar="ID", help="run id or unique prefix")

    compare = sub.add_parser("compare", parents=[common], help="runs side by side")
    compare.add_argument("run_ids", metavar="ID", nargs="+", help="two or more run ids or prefixes")
    remove = sub.add_parser("rm", parents=[common], help="remove runs from the catalog and "
                            "delete their run directories")
    remove.add_argument("run_ids", metavar="ID", nargs="+", help="run ids or unique prefixes")
    remove.add_argument("--keep-files", action="store_true",
                        help="keep the run directories, remove only the catalog rows")
    rerun = sub.add_parser("rerun", parents=[common], help="run a recorded run's experiment "
                           "and overrides again (a new run)")
    rerun.add_argument("run_id", metavar="ID", help="run id or unique prefix")
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
        elif args.command == "rerun":
            return _cmd_rerun(_open_catalog(_root(args.root)), args)
        else:
            catalog = _open_catalog(_root(args.root))
            output = {"list": _cmd_list, "show": _cmd_show, "compare": _cmd_compare,
                      "rm": _cmd_rm}[args.command](catalog, args)
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


def _positive(text: str) -> int:
    value = _non_negative(text)
    if not 1 <= value <= 17:
        raise argparse.ArgumentTypeError(f"{value} is out of range: use 1 <= N <= 17")
    return value


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
                           metric=args.metric, limit=args.limit, include_rejected=args.all)
    if args.format == "json":
        return to_json([record_json(r) for r in records])
    if not records:
        return "no runs match"
    short = short_ids(catalog.ids())
    digits = metric_digits(records, args.digits)
    header = ["id", "experiment", "status", "start", "wall time", "overrides", "metrics"]
    rows = [[short.get(r.id, r.id), r.experiment, r.status, short_time(r.start_time),
             duration(r.wall_time_s), clip(" ".join(r.overrides)),
             clip(metrics_cell(r.metrics, digits))] for r in records]
    return table(header, rows)


def _cmd_show(catalog: Catalog, args: argparse.Namespace) -> str:
    record = catalog.get(args.run_id)
    if args.format == "json":
        return to_json(record_json(record))
    lines = [
        ("id", record.id), ("experiment", record.experiment),
        ("status", record.status if record.status == record.recorded_status
         else f"{record.status} (recorded: {record.recorded_status})"),
        ("start", record.start_time or "-"), ("end", record.end_time or "-"),
        ("wall time", duration(record.wall_time_s)), ("path", record.path or "-"),
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
        out += [f"  {n:<{name_width}}  {number(v, args.digits or 6)}"
                for n, v in sorted(record.metrics.items())]
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
        return to_json({
            "runs": [r.id for r in records],
            "experiment": [r.experiment for r in records],
            "status": [r.status for r in records],
            "wall_time_s": [finite(r.wall_time_s) for r in records],
            "git_commit": [r.git_commit for r in records],
            "differing": differing,
            "metrics": {n: [finite(v) for v in values] for n, values in metrics.items()},
        })
    short = short_ids(catalog.ids())
    header = [""] + [short.get(r.id, r.id) for r in records]
    rows = [["experiment"] + [r.experiment for r in records],
            ["status"] + [r.status for r in records],
            ["start"] + [short_time(r.start_time) for r in records],
            ["wall time"] + [duration(r.wall_time_s) for r in records]]
    if len({r.git_commit for r in records}) > 1:
        rows.append(["git commit"] + [r.git_commit[:10] or "-" for r in records])
    digits = metric_digits(records, args.digits)
    sections = [table(header, rows)]
    sections.append(table(["differing setting"] + header[1:],
                          [[k] + [clip("-" if v is None else v) for v in vals]
                            for k, vals in differing.items()])
                    if differing else "differing settings: none")
    sections.append(table(["metric"] + header[1:],
                          [[n] + [number(v, digits[n]) for v in vals]
                            for n, vals in metrics.items()])
                    if metrics else "metrics: none")
    return "\n\n".join(sections)


def _cmd_rm(catalog: Catalog, args: argparse.Namespace) -> str:
    import shutil

    records = [catalog.get(run_id) for run_id in args.run_ids]
    running = [r for r in records if r.status == "running"]
    if running:
        raise PointatlasError(f"run {running[0].id} is still running (pid {running[0].pid} on "
                              f"{running[0].host}): stop it first, then remove it")
    removed = []
    for record in records:
        folder = Path(record.path) if record.path else None
        if not args.keep_files and folder and folder.is_dir() and (
                (folder / "run.json").exists() or (folder / "results.nc").exists()):
            shutil.rmtree(folder)
        catalog.forget(record.id)
        removed.append({"id": record.id, "path": record.path,
                        "files_removed": bool(folder) and not args.keep_files})
    if args.format == "json":
        return to_json({"removed": removed})
    return "\n".join(f"removed {r['id']}" + (f" and {r['path']}" if r["files_removed"] else "")
                     for r in removed)


def _cmd_rerun(catalog: Catalog, args: argparse.Namespace) -> int:
    """Run ``pointatlas`` with the recorded experiment and overrides (and this outputs root)."""
    import subprocess

    record = catalog.get(args.run_id)
    overrides = [o for o in record.overrides if not o.startswith(("outputs_root=", "experiment="))]
    experiment = ([f"experiment={record.experiment}"] if record.experiment != "none"
                  else ["~experiment"])
    command = [str(Path(sys.executable).parent / "pointatlas"), *experiment, *overrides,
               f"outputs_root={_root(args.root)}"]
    print(f"{PROG}: rerunning {record.id}: pointatlas {' '.join(command[1:])}", file=sys.stderr,
          flush=True)
    return subprocess.call(command)


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
        return to_json({"catalog": str(catalog_path(root)), "moved_aside": list(map(str, report.moved_aside)),
                      "completed": report.completed, "failed": report.failed,
                      "unfinished": report.unfinished,
                      "unreadable": list(map(str, report.unreadable))})
    return report.text(catalog_path(root))


def _cmd_gc(args: argparse.Namespace) -> str:
    from .catalog_repair import collect_garbage

    root = _existing_root(args)
    removed = collect_garbage(root)
    if args.format == "json":
        return to_json({"removed": list(map(str, removed))})
    return f"removed {len(removed)} leftover temporary files under {root}" + "".join(
        f"\n  {p}" for p in removed)


if __name__ == "__main__":
    sys.exit(main())
