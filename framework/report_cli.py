"""``pointatlas-report PATH [--out DIR] [--format html,md] [--generic-plots]``: write the
report of a run or sweep.

PATH is a run directory (it holds ``results.nc``), a ``results.nc`` file, or a sweep directory
(its sub-directories hold ``results.nc``). The report goes to ``report.html`` / ``report.md``
in ``--out`` (default: PATH, or the folder of a ``results.nc`` file).

A sweep report shows the study's own sweep figures first. The generic plots (each metric that
varies against each swept numeric parameter) are added only when no plugin supplied sweep
figures, unless ``--generic-plots`` (always) or ``--no-generic-plots`` (never) is given.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .errors import InputError, PointatlasError

RESULTS = "results.nc"


def classify(path: Path) -> tuple[str, Path]:
    """('run', run dir) or ('sweep', sweep dir) for ``path``; InputError when neither."""
    if not path.exists():
        raise InputError(f"{path} does not exist. Give a run directory, a results.nc file or a sweep directory.")
    if path.is_file():
        if path.suffix == ".nc":
            return "run", path.parent
        raise InputError(f"{path} is a file but not a results.nc. Give a run or sweep directory.")
    if (path / RESULTS).is_file():
        return "run", path
    if any((child / RESULTS).is_file() for child in path.iterdir() if child.is_dir()):
        return "sweep", path
    raise InputError(
        f"No {RESULTS} in {path} nor in its sub-directories. Give a run directory "
        f"(with {RESULTS}) or a sweep directory (with one sub-directory per run)."
    )


def _open_run(path: Path):
    from .results import open_run

    return open_run(path)


def _open_sweep(path: Path):
    from .sweep import open_sweep

    return open_sweep(path)


def parse_formats(text: str) -> tuple[str, ...]:
    from .report import FORMATS

    formats = tuple(f.strip().lower() for f in text.split(",") if f.strip())
    bad = [f for f in formats if f not in FORMATS]
    if bad or not formats:
        raise InputError(
            f"--format {text!r}: unknown format(s) {', '.join(bad) or '(empty)'}; "
            f"valid: {','.join(FORMATS)} (comma separated, e.g. --format html,md)."
        )
    return formats


def make_report(path: str | Path, out: str | Path | None = None,
                formats: tuple[str, ...] = ("html", "md"),
                generic: bool | None = None) -> list[Path]:
    """Open PATH (run or sweep), build its report and write it; return the written files.
    ``generic`` is :func:`pointatlas.report.build_sweep_report`'s (None: only when the study
    has no sweep figures of its own); a run report has no generic plots."""
    from .report import build_run_report, build_sweep_report, write_report

    path = Path(path)
    kind, directory = classify(path)
    if kind == "run":
        report = build_run_report(_open_run(path), directory)
    else:
        report = build_sweep_report(_open_sweep(directory), directory, generic=generic)
    return write_report(report, Path(out) if out is not None else directory, formats)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="pointatlas-report",
        description="Write a self-contained HTML report and a Markdown twin for a run or a sweep.",
    )
    parser.add_argument("path", help="run directory, results.nc file, or sweep directory")
    parser.add_argument("--out", default=None, help="output directory (default: PATH)")
    parser.add_argument("--format", default="html,md", help="comma-separated: html, md (default: html,md)")
    parser.add_argument(
        "--generic-plots", action=argparse.BooleanOptionalAction, default=None,
        help="sweeps: add a plot of each metric that varies against each swept numeric "
             "parameter (--no-generic-plots: never). Default: only when the study supplies "
             "no sweep figures of its own. Ignored for a run.")
    args = parser.parse_args(argv)
    try:
        written = make_report(args.path, args.out, parse_formats(args.format), args.generic_plots)
    except PointatlasError as exc:
        print(f"pointatlas-report: error: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:
        print(f"pointatlas-report: error: {exc}", file=sys.stderr)
        return 1
    for file in written:
        print(file)
    return 0


if __name__ == "__main__":
    sys.exit(main())
