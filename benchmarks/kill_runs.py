"""Kill runs at random moments and count what the kills damaged (issue 15 acceptance).

Each trial starts a real ``pointatlas`` command and ends it with ``kill -9``:

- ``random``: after a uniformly random delay within the run's typical duration;
- ``results_write``: the moment a temporary ``.results.nc.*.tmp`` appears (during the write);
- ``increments_write``: the moment a temporary ``.increments.nc.*.tmp`` appears (a nonlinear
  shell path, during the write of its increments file).

Two kinds of run: ``surface`` (the default sphere_willmore study, 1 500 points) and ``shell``
(the open hemisphere along its nonlinear load path, 200 points, to 0.3 of the load in
increments of 0.25 of it, cut where Newton needs it). While a shell
run works, the script reads the published ``increments.nc`` every few milliseconds and keeps
the largest number of increments it saw: those had converged and been written before the
kill. After each kill it counts

- **corrupt files**: a ``results.nc`` or ``increments.nc`` that exists but cannot be read;
- **lost increments**: increments seen in ``increments.nc`` before the kill but missing from
  it afterwards;
- **stale rows**: the killed run's catalog row does not tell the truth: not ``died`` (nor
  ``completed`` with its results written before the kill), or no row although the run had
  started writing its directory;
- after all trials, ``pointatlas-runs gc`` runs and the temporary files still left are
  counted (**leftovers**).

With ``--resume N``, N killed shell runs are resumed (``study.resume_from``) and compared
with an uninterrupted run: same load factors, every variable within 1e-8.

Usage: python benchmarks/kill_runs.py [out.nc] [--kills 60] [--seed 0] [--resume 3]
Writes benchmarks/results/kill_runs.nc by default and prints a table.
"""
from __future__ import annotations

import argparse
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

BIN = Path(sys.executable).parent
RUNS = {
    "surface": ["source.n_points=1500"],
    "shell": ["experiment=shell_open_hemisphere", "source.n_points=200", "study.n_increments=4",
              "study.max_load_factor=0.3"],
}
MODES = ("random", "results_write", "increments_write")


def spawn(args: list[str], root: Path, run_dir: Path) -> subprocess.Popen:
    env = {**os.environ, "HYDRA_FULL_ERROR": "0", "PYTHONWARNINGS": "ignore",
           "MPLBACKEND": "Agg"}
    return subprocess.Popen([str(BIN / "pointatlas"), *args, f"outputs_root={root}",
                             f"hydra.run.dir={run_dir}"], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, env=env, cwd=root.parent)


def readable(path: Path) -> bool:
    import netCDF4

    try:
        with netCDF4.Dataset(path) as nc:
            nc.ncattrs()
            for name in nc.variables:
                nc.variables[name][...]
        return True
    except Exception:  # noqa: BLE001 - any failure to read is a corrupt file
        return False


def n_increments(path: Path) -> int:
    import netCDF4

    try:
        with netCDF4.Dataset(path) as nc:
            return len(nc.dimensions["increment"])
    except Exception:  # noqa: BLE001 - not there yet, or being replaced
        return 0


def typical_seconds(kind: str, root: Path) -> float:
    run_dir = root.parent / f"typical_{kind}"
    t0 = time.perf_counter()
    proc = spawn(RUNS[kind], root, run_dir)
    proc.wait()
    if proc.returncode != 0:
        raise SystemExit(f"the {kind} run fails without a kill: {' '.join(RUNS[kind])}")
    return time.perf_counter() - t0


def trial(kind: str, mode: str, root: Path, run_dir: Path, duration: float,
          rng: random.Random) -> dict:
    proc = spawn(RUNS[kind], root, run_dir)
    t0 = time.perf_counter()
    delay = rng.uniform(0.2, duration) if mode == "random" else None
    pattern = ".results.nc.*.tmp" if mode == "results_write" else ".increments.nc.*.tmp"
    seen, in_write = 0, False
    while proc.poll() is None:
        if kind == "shell":
            seen = max(seen, n_increments(run_dir / "increments.nc"))
        if delay is not None and time.perf_counter() - t0 >= delay:
            break
        if delay is None and run_dir.is_dir() and any(run_dir.glob(pattern)):
            in_write = True
            break
        time.sleep(0.002)
    finished = proc.poll() is not None
    if not finished:
        in_write = in_write or (run_dir.is_dir() and any(run_dir.glob(".*.tmp")))
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    after = n_increments(run_dir / "increments.nc")
    corrupt = sum(1 for name in ("results.nc", "increments.nc")
                  if (run_dir / name).exists() and not readable(run_dir / name))
    status = row_status(root, run_dir)
    started = run_dir.is_dir() and (run_dir / "run.json").exists()
    # truthful: a killed run reads 'died', or 'completed' when it had written its results and
    # its row before the kill; stale: 'running' for a dead process, or no row once started
    truthful = status == "died" or (status == "completed" and
                                    (run_dir / "results.nc").exists())
    stale = 0 if finished else int(not truthful and (status is not None or started))
    return {"kind": kind, "mode": mode, "killed_at_s": time.perf_counter() - t0,
            "finished": finished, "in_write": in_write, "seen": seen, "after": after,
            "lost": max(seen - after, 0), "corrupt": corrupt, "status": status or "no row",
            "stale": stale}


def row_status(root: Path, run_dir: Path) -> str | None:
    from pointatlas.catalog import Catalog

    path = root / "catalog.sqlite"
    if not path.exists():
        return None
    rows = [r for r in Catalog(path).runs() if r.path == str(run_dir.resolve())]
    return rows[-1].status if rows else None


def resume_check(root: Path, killed: list[Path], reference: Path) -> list[float]:
    """Resume killed shell runs; the largest difference to the uninterrupted run, per run."""
    import xarray as xr

    ref = xr.open_dataset(reference / "results.nc").load()
    out = []
    for run_dir in killed:
        target = run_dir.parent / (run_dir.name + "_resumed")
        proc = spawn([*RUNS["shell"], f"study.resume_from={run_dir}"], root, target)
        proc.wait()
        if proc.returncode != 0:
            out.append(float("inf"))
            continue
        got = xr.open_dataset(target / "results.nc").load()
        worst = 0.0
        if got.sizes.get("increment") != ref.sizes.get("increment"):
            worst = float("inf")
        for name, var in ref.data_vars.items():
            if var.attrs.get("units") == "s" or var.dtype.kind not in "fiu" or name not in got:
                continue  # wall times differ between any two runs
            a, b = np.asarray(var.values, float), np.asarray(got[name].values, float)
            if a.shape != b.shape:
                worst = float("inf")
                continue
            scale = max(float(np.nanmax(np.abs(a))) if a.size else 0.0, 1.0)
            diff = np.abs(a - b)[np.isfinite(a) | np.isfinite(b)]
            worst = max(worst, float(np.nanmax(diff)) / scale if diff.size else 0.0)
        out.append(worst)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default=str(Path(__file__).parent / "results" / "kill_runs.nc"))
    parser.add_argument("--kills", type=int, default=60)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--resume", type=int, default=3)
    args = parser.parse_args()
    rng = random.Random(args.seed)
    work = Path(tempfile.mkdtemp(prefix="kill_runs_"))
    root = work / "outputs"
    duration = {kind: typical_seconds(kind, root) for kind in RUNS}
    print("typical durations: " + ", ".join(f"{k} {v:.1f} s" for k, v in duration.items()),
          flush=True)
    plan = [("surface", "random"), ("surface", "results_write"), ("shell", "random"),
            ("surface", "random"), ("shell", "increments_write"), ("surface", "results_write"),
            ("shell", "results_write"), ("shell", "increments_write")]
    trials = []
    for i in range(args.kills):
        kind, mode = plan[i % len(plan)]
        trials.append(trial(kind, mode, root, work / f"run{i:03d}", duration[kind], rng))
        t = trials[-1]
        print(f"{i:3d} {kind:7s} {mode:16s} t={t['killed_at_s']:6.2f} s in_write={t['in_write']!s:5s} "
              f"finished={t['finished']!s:5s} increments {t['seen']}->{t['after']} "
              f"corrupt={t['corrupt']} row={t['status']}", flush=True)
    gc = subprocess.run([str(BIN / "pointatlas-runs"), "gc", "--root", str(root)],
                        capture_output=True, text=True)
    leftovers = sum(1 for p in work.rglob(".*.tmp")) + sum(1 for p in work.rglob("*.partial.nc"))
    killed = [t for t in trials if not t["finished"]]
    resumed = []
    if args.resume:
        candidates = [work / f"run{i:03d}" for i, t in enumerate(trials)
                      if t["kind"] == "shell" and not t["finished"] and t["after"] >= 1]
        resumed = resume_check(root, candidates[:args.resume], work / "typical_shell")
    totals = {"kills": len(killed), "kills_in_write": sum(t["in_write"] for t in killed),
              "corrupt_files": sum(t["corrupt"] for t in trials),
              "lost_increments": sum(t["lost"] for t in trials),
              "stale_rows": sum(t["stale"] for t in trials), "leftovers_after_gc": leftovers}
    print(gc.stdout.strip().splitlines()[0] if gc.stdout else gc.stderr.strip())
    print("\n" + "\n".join(f"{k:20s} {v}" for k, v in totals.items()))
    if resumed:
        print(f"resumed runs vs uninterrupted: max relative difference {max(resumed):.3g} "
              f"over {len(resumed)} runs (wall times excluded)")
    write(args.out, trials, totals, resumed)
    shutil.rmtree(work, ignore_errors=True)


def write(out: str, trials: list[dict], totals: dict, resumed: list[float]) -> None:
    import xarray as xr

    n = len(trials)
    ds = xr.Dataset(
        {key: (("trial",), np.array([t[key] for t in trials]), {"long_name": key, "units": unit})
         for key, unit in (("killed_at_s", "s"), ("in_write", "1"), ("seen", "1"),
                           ("after", "1"), ("lost", "1"), ("corrupt", "1"), ("stale", "1"))},
        coords={"trial": ("trial", np.arange(n), {"long_name": "trial", "units": "1"}),
                "kind": ("trial", [t["kind"] for t in trials], {"long_name": "run kind", "units": "1"}),
                "mode": ("trial", [t["mode"] for t in trials], {"long_name": "kill moment", "units": "1"})})
    for key, value in totals.items():
        ds[key] = ((), value, {"long_name": key.replace("_", " "), "units": "1"})
    if resumed:
        ds["resume_max_difference"] = ((), max(resumed), {"long_name": "largest relative "
                                                          "difference resumed vs uninterrupted",
                                                          "units": "1"})
    for name in ("in_write",):
        ds[name] = ds[name].astype("i1")
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
