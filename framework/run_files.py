"""Names of the files in a run directory, and the removal of what interrupted writes left.

Standard library only (``pointatlas-runs`` imports it).
"""
from __future__ import annotations

import os
from pathlib import Path

#: the results of a finished run (:mod:`pointatlas.results`)
RESULTS_NAME = "results.nc"
#: what a run directory says of its run from the start (``pointatlas-runs repair`` reads it)
RUN_FILE = "run.json"
#: the message of a failed run
ERROR_FILE = "error.txt"
#: glob patterns of the temporary files an interrupted write leaves in a run directory
PARTIAL_PATTERNS = (".*.tmp", "*.partial.nc")


def remove_partial_files(run_dir: str | os.PathLike) -> list[Path]:
    """Delete the temporary files interrupted writes left in ``run_dir``; return them."""
    removed = []
    folder = Path(run_dir)
    if not folder.is_dir():
        return removed
    for pattern in PARTIAL_PATTERNS:
        for leftover in folder.glob(pattern):
            if leftover.is_file():
                leftover.unlink(missing_ok=True)
                removed.append(leftover)
    return removed
