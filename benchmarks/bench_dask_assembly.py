"""Shell (Kirchhoff-Love) tangent assembly on a hemisphere: executor=local vs dask 1 and 2 workers.

Runs the CLI ``pointatlas experiment=shell_hemisphere source.n_points=N`` (the quarter model
of the pinched hemisphere, linear) once per configuration, each in a fresh process:

* ``local``: ``executor=local`` (numba threads: the default);
* ``dask1`` / ``dask2``: ``executor=dask executor.scheduler_address=<a LocalCluster of 1|2
  worker processes × 1 thread, NUMBA_NUM_THREADS=1, started by the child>`` (the same
  workers as ``executor.n_workers=1|2 executor.threads_per_worker=1`` would start; started
  here so that a warm-up run, ``--warmup-n`` points, compiles numba on them first).

Each child first runs the CLI on ``--warmup-n`` points with the same executor (numba JIT in
the client and on the workers), then the timed run.

The child process wraps (monkeypatches, timing only) ``Assembler.tangent`` and
``Assembler.residual`` and ``DaskExecutor.map`` (wall per call and per map ``desc``), records
the workers' ru_maxrss (``client.run``) just before the executor closes, samples the RSS of
itself and of its child processes (the Dask workers) every 0.1 s with psutil, and then calls
``pointatlas.cli.main``. Reported: process wall time, the run's ``time_*`` variables
(``pointatlas.open_run``), the tangent/residual assembly wall times, peak RSS of the client and
of each worker, and the largest relative difference of every numeric result variable
(displacement first) of each dask run vs the local run.

The memory estimate of the model (atlas with basis + tangent of 3 DOF/node and its solve, as
``build_surface_model`` checks it) is printed for the chosen N; ``--estimate-only`` prints it
for a few sizes and stops.

Usage:
  python benchmarks/bench_dask_assembly.py --n 20000 --configs local dask1 dask2
Writes/updates benchmarks/results/dask_assembly.json.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import threading
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).parent / "results"
DEFAULT_JSON = RESULTS / "dask_assembly.json"
CONFIGS = {"local": ["executor=local"],
           "dask1": ["executor=dask", "executor.n_workers=1", "executor.threads_per_worker=1"],
           "dask2": ["executor=dask", "executor.n_workers=2", "executor.threads_per_worker=1"]}


def estimate_bytes(n_points: int, ghost_fraction: float = 0.03) -> dict:
    """The model's memory estimate (build_surface_model's check), nodes ≈ N (1 + ghosts)."""
    from pointatlas_atlas.atlas import Atlas, AtlasSettings
    from pointatlas_atlas.memory_estimate import estimate_tangent_bytes, support_size

    s = AtlasSettings()
    nodes = int(n_points * (1 + ghost_fraction))
    atlas = Atlas(s, None, None, None).estimated_bytes(nodes, n_points, 3, 2, keep_basis=True)
    tangent = estimate_tangent_bytes(nodes, 3, support_size(2, s.gamma_lme, s.tol_lme))
    return {"atlas_with_basis": atlas, "tangent_and_solve": tangent, "total": atlas + tangent}


def worker_maxrss() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def vm_hwm_bytes() -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) * 1024
    return -1


class TreeSampler(threading.Thread):
    """Peak RSS (bytes) of this process and of each of its descendants, every ``dt`` s."""

    def __init__(self, dt: float = 0.1):
        super().__init__(daemon=True)
        import psutil

        self.me = psutil.Process()
        self.peak: dict = {}
        self.names: dict = {}
        self.dt, self.stop_flag = dt, threading.Event()

    def run(self):
        while not self.stop_flag.is_set():
            try:
                procs = [self.me] + self.me.children(recursive=True)
            except Exception:  # noqa: BLE001
                procs = [self.me]
            for p in procs:
                try:
                    rss = p.memory_info().rss
                    if p.pid not in self.names:
                        self.names[p.pid] = " ".join(p.cmdline())[:120]
                except Exception:  # noqa: BLE001 — gone
                    continue
                self.peak[p.pid] = max(self.peak.get(p.pid, 0), rss)
            self.stop_flag.wait(self.dt)

    def stop(self):
        self.stop_flag.set()
        self.join(2)


def child(args) -> None:
    from pointatlas_executors.dask_executor import DaskExecutor
    from pointatlas_kit.assembler import Assembler

    record = {"config": args.config, "n_points": args.n, "calls": defaultdict(list),
              "worker_ru_maxrss_bytes": {}, "load_average_start": os.getloadavg()}

    def timed(name, fn):
        def wrapper(*a, **kw):
            t0 = time.perf_counter()
            try:
                return fn(*a, **kw)
            finally:
                record["calls"][name].append(time.perf_counter() - t0)
        return wrapper

    Assembler.tangent = timed("tangent", Assembler.tangent)
    Assembler.residual = timed("residual", Assembler.residual)
    orig_map, orig_close = DaskExecutor.map, DaskExecutor.close

    def map_(self, fn, items, **kw):
        t0 = time.perf_counter()
        try:
            return orig_map(self, fn, items, **kw)
        finally:
            record["calls"]["map:" + kw.get("desc", "tasks")].append(time.perf_counter() - t0)

    def close_(self):
        client = getattr(self, "_client", None)
        if client is not None:
            try:
                record["worker_ru_maxrss_bytes"].update(
                    {a: int(v) for a, v in sorted(client.run(worker_maxrss).items())})
                record["worker_pids"] = {a: int(v) for a, v in client.run(os.getpid).items()}
            except Exception as exc:  # noqa: BLE001
                record["worker_ru_maxrss_error"] = repr(exc)
        return orig_close(self)

    DaskExecutor.map, DaskExecutor.close = map_, close_
    from pointatlas.cli import main as cli_main

    def run_cli(n, rundir, executor_args):
        cli = ["experiment=shell_hemisphere", f"source.n_points={n}", *executor_args,
               f"outputs_root={rundir}/outputs", f"hydra.run.dir={rundir}/run"]
        t0 = time.perf_counter()
        try:
            cli_main(cli)
            code = 0
        except SystemExit as exc:
            code = exc.code or 0
        return code, time.perf_counter() - t0

    cluster = None
    executor_args = CONFIGS[args.config]
    if args.config != "local":
        import logging

        from distributed import LocalCluster

        k = int(args.config[-1])
        cluster = LocalCluster(n_workers=k, threads_per_worker=1, processes=True,
                               dashboard_address=":0", silence_logs=logging.WARNING,
                               env={"NUMBA_NUM_THREADS": "1"})
        executor_args = ["executor=dask", f"executor.scheduler_address={cluster.scheduler_address}"]
    if args.warmup_n:
        # numba JIT of the atlas and the shell's kernels, here and (dask) on the workers
        code, wall = run_cli(args.warmup_n, f"{args.rundir}_warmup", executor_args)
        record["warmup"] = {"n_points": args.warmup_n, "wall_s": wall, "exit_code": code,
                            "calls": dict(record["calls"])}
        record["calls"] = defaultdict(list)
    record["cli_args"] = executor_args
    sampler = TreeSampler()
    sampler.start()
    code, record["cli_wall_s"] = run_cli(args.n, args.rundir, executor_args)
    sampler.stop()
    if cluster is not None:
        cluster.close()
    record["exit_code"] = code
    record["client_ru_maxrss_bytes"] = worker_maxrss()
    record["client_vmhwm_bytes"] = vm_hwm_bytes()
    me = os.getpid()
    record["psutil_peak_rss_bytes"] = {
        ("client" if pid == me else f"pid{pid}"): {"peak": v, "cmd": sampler.names.get(pid, "")}
        for pid, v in sampler.peak.items()}
    wp = {v: a for a, v in record.get("worker_pids", {}).items()}
    record["worker_psutil_peak_rss_bytes"] = {wp[pid]: v for pid, v in sampler.peak.items()
                                              if pid in wp}
    record["load_average_end"] = os.getloadavg()
    record["calls"] = dict(record["calls"])
    Path(args.child_json).write_text(json.dumps(record, indent=1))
    sys.exit(code)


def numeric_differences(a, b) -> dict:
    out = {}
    for name in a.data_vars:
        if name.startswith("time_") or a[name].dtype.kind not in "fiu" or name not in b:
            continue
        x, y = a[name].values.astype(float), b[name].values.astype(float)
        if x.shape != y.shape:
            out[name] = float("inf")
            continue
        scale = np.maximum(np.abs(x), 1e-300)
        out[name] = float(np.nanmax(np.abs(x - y) / scale)) if x.size else 0.0
    return out


def gib(b):
    return "-" if b is None else f"{b / 2**30:.2f}"


def driver(args):
    import pointatlas

    out = Path(args.json)
    data = json.loads(out.read_text()) if out.exists() else {"runs": {}, "comparisons": {}}
    est = estimate_bytes(args.n)
    print(f"N={args.n}: estimated memory {gib(est['total'])} GiB (atlas with basis "
          f"{gib(est['atlas_with_basis'])}, tangent+solve {gib(est['tangent_and_solve'])})",
          flush=True)
    tmp = Path(args.workdir or tempfile.mkdtemp(prefix="bench_dask_assembly_"))
    runs = {}
    for cfg in args.configs:
        key = f"N{args.n}_{cfg}"
        rundir = tmp / key
        rj = tmp / f"{key}.json"
        cmd = [sys.executable, __file__, "--config", cfg, "--n", str(args.n),
               "--warmup-n", str(args.warmup_n),
               "--rundir", str(rundir), "--child-json", str(rj)]
        print("$", " ".join(cmd), flush=True)
        t0 = time.perf_counter()
        p = subprocess.run(cmd)
        wall = time.perf_counter() - t0
        r = json.loads(rj.read_text()) if rj.exists() else {}
        r.update(process_wall_s=wall, returncode=p.returncode, estimate_bytes=est,
                 run_dir=str(rundir / "run"))
        if p.returncode == 0:
            ds = pointatlas.open_run(rundir / "run")
            r["time_vars"] = {v: float(ds[v].values) for v in ds.data_vars
                              if v.startswith("time_") and ds[v].size == 1}
            if "displacement" in ds:
                r["displacement"] = ds["displacement"].values.tolist() \
                    if ds["displacement"].size < 10 else None
            runs[cfg] = ds
        log = "".join(q.read_text() for q in (rundir / "run").glob("*.log"))
        r["log_assembly_lines"] = [ln for ln in log.splitlines() if "assembly" in ln][:20]
        data["runs"][key] = r
        out.write_text(json.dumps(data, indent=1))
    ref = "local" if "local" in runs else None
    for cfg, ds in runs.items():
        if ref and cfg != ref:
            diff = numeric_differences(runs[ref], ds)
            data["comparisons"][f"N{args.n}_{cfg}_vs_{ref}"] = diff
            worst = max(diff.values()) if diff else float("nan")
            print(f"{cfg} vs {ref}: displacement rel. diff {diff.get('displacement')}, "
                  f"largest over {len(diff)} numeric variables {worst:.3e}")
    out.write_text(json.dumps(data, indent=1))
    cols = ["run", "process wall", "cli wall", "tangent (s, each call)", "residual (s)",
            "client peak GiB", "worker peak GiB"]
    print("| " + " | ".join(cols) + " |\n|" + "---|" * len(cols))
    for key, r in data["runs"].items():
        if "calls" not in r:
            continue
        c = r["calls"]
        wk = ", ".join(gib(v) for v in r.get("worker_ru_maxrss_bytes", {}).values()) or "-"
        print(f"| {key} | {r['process_wall_s']:.1f} | {r.get('cli_wall_s', float('nan')):.1f} | "
              f"{', '.join(f'{v:.2f}' for v in c.get('tangent', []))} | "
              f"{', '.join(f'{v:.2f}' for v in c.get('residual', []))} | "
              f"{gib(max(r['client_ru_maxrss_bytes'], r['client_vmhwm_bytes']))} | {wk} |")
    for key, r in data["runs"].items():
        if r.get("time_vars"):
            print(key, {k: round(v, 2) for k, v in r["time_vars"].items()})
    print("wrote", out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="\n".join(__doc__.splitlines()[1:]))
    ap.add_argument("--n", type=int, default=20_000, help="source.n_points")
    ap.add_argument("--configs", nargs="+", default=list(CONFIGS), choices=list(CONFIGS))
    ap.add_argument("--json", default=str(DEFAULT_JSON), help="results JSON (updated)")
    ap.add_argument("--workdir", help="where the run directories go (default: a temp dir)")
    ap.add_argument("--estimate-only", action="store_true",
                    help="print the memory estimate for some sizes and stop")
    ap.add_argument("--warmup-n", type=int, default=500,
                    help="points of a warm-up run (same executor, same workers) before the "
                         "timed one; 0: none (cold: numba compiles inside the timed run)")
    ap.add_argument("--config", choices=list(CONFIGS), help="child: run this one here")
    ap.add_argument("--rundir", help="child: run directory")
    ap.add_argument("--child-json", help="child: write the record here")
    args = ap.parse_args(argv)
    if args.estimate_only:
        for n in (5_000, 10_000, 20_000, 25_000, 30_000, 50_000, 100_000, 200_000, args.n):
            e = estimate_bytes(n)
            print(f"N={n}: {gib(e['total'])} GiB (atlas+basis {gib(e['atlas_with_basis'])}, "
                  f"tangent+solve {gib(e['tangent_and_solve'])})")
        return
    if args.config:
        child(args)
    else:
        driver(args)


if __name__ == "__main__":
    main()
