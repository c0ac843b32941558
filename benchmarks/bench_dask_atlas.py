"""Atlas of an N-point sphere on executor=local vs a Dask LocalCluster of 1 and 2 workers.

Quasi-uniform Fibonacci points on the unit sphere (built here), AtlasSettings(markers_per_patch
=150, quadrature_order=--order), PCA embedder, LME and Shepard PU as make_atlas of
tests/plugins/executors/test_dask_executor.py. Configurations (``--config``):

* ``local``: SerialExecutor in this process (numba threads: the default);
* ``dask1`` / ``dask2``: DaskExecutor(scheduler_address=...) on a LocalCluster started here
  with 1 / 2 worker processes of 1 thread each (NUMBA_NUM_THREADS=1 on the workers).

Each configuration runs in a fresh process (the driver starts one subprocess per config), so
the peak RSS is that run's. Numba is warmed first (a 2 000-point atlas built once with the
same executor, i.e. on the workers for dask). Phases (wall s):

* partition = metis (initial partition_markers) + embeddings (the refine_partition loop; on
  dask its prefetch maps are timed separately) + rest (k-d tree, PU fit, ...), all on the
  client except the embedding maps;
* charts (on dask: the map and the client rest);
* quadrature = map (per-chart Gauss points; serial loop on local) + orient (orient_atlas, on
  the client).

Client-only time = total - Σ (wall of the executor.map calls); serial fraction s = client-only
/ total, Amdahl limit 1/s. Per-task overhead: 200 trivial tasks (pointatlas.testing.
conformance_task) mapped on the cluster three ways (DaskExecutor.map batched as in a run;
DaskExecutor.map with one task per item; raw client.map), wall / 200. Mean task durations of
the real maps come from the scheduler's task stream. Peak RSS: the client's ru_maxrss and
VmHWM, and every 0.1 s psutil samples of client and worker processes; the workers'
ru_maxrss via client.run.

Integrals: area and ∫K (both 4π). The driver compares the arrays (labels, weights, H, K) of
every dask run with the local run of the same N and order (or dask1 when there is no local
run) and prints the largest relative difference.

Usage:
  python benchmarks/bench_dask_atlas.py --n 100000 --order 6 --configs local dask1 dask2
  python benchmarks/bench_dask_atlas.py --n 1000000 --order 1 --configs dask1 dask2
Writes/updates benchmarks/results/dask_atlas.json (one entry per N, order, config).
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
DEFAULT_JSON = RESULTS / "dask_atlas.json"
CONFIGS = {"local": 0, "dask1": 1, "dask2": 2}
FOUR_PI = 4 * np.pi


def fibonacci_sphere(n: int) -> np.ndarray:
    """Quasi-uniform points on the unit sphere (Fibonacci lattice)."""
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    r = np.sqrt(1 - z * z)
    t = np.pi * (1 + 5**0.5) * k
    return np.c_[r * np.cos(t), r * np.sin(t), z]


def make_atlas(order: int):
    import pointatlas
    from pointatlas_atlas.atlas import Atlas, AtlasSettings

    s = AtlasSettings(markers_per_patch=150, quadrature_order=order)
    return Atlas(
        s, make_embedder=lambda: pointatlas.load_plugin("embedders", "pca")(n_components=2),
        make_lme=lambda: pointatlas.load_plugin("approximants", "lme")(
            gamma=s.gamma_lme, tol=s.tol_lme, outside="flag"),
        make_pu=lambda: pointatlas.load_plugin("approximants", "shepard")(
            gamma=s.gamma_pu, tol=s.tol_pu, outside="flag"))


# -- child: one configuration --------------------------------------------------------------
class Timers:
    def __init__(self):
        self.t = defaultdict(float)
        self.n = defaultdict(int)
        self.active = False

    def wrap(self, name, fn):
        def timed(*a, **kw):
            t0 = time.perf_counter()
            try:
                return fn(*a, **kw)
            finally:
                if self.active:
                    self.t[name] += time.perf_counter() - t0
                    self.n[name] += 1
        return timed


class RssSampler(threading.Thread):
    """Peak RSS (bytes) of the given pids, sampled every ``dt`` s with psutil."""

    def __init__(self, pids: dict, dt: float = 0.1):
        super().__init__(daemon=True)
        import psutil

        self.procs = {name: psutil.Process(pid) for name, pid in pids.items()}
        self.peak = {name: 0 for name in pids}
        self.dt, self.stop_flag = dt, threading.Event()

    def run(self):
        while not self.stop_flag.is_set():
            for name, p in self.procs.items():
                try:
                    self.peak[name] = max(self.peak[name], p.memory_info().rss)
                except Exception:  # noqa: BLE001 — a process gone
                    pass
            self.stop_flag.wait(self.dt)

    def stop(self):
        self.stop_flag.set()
        self.join(2)
        return dict(self.peak)


def vm_hwm_bytes() -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) * 1024
    return -1


def worker_maxrss() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def task_overhead(address: str, repeats: int = 3) -> dict:
    """Wall / 200 of 200 trivial tasks on the cluster (median of ``repeats``), three ways."""
    from pointatlas.executor import using_executor
    from pointatlas.testing import conformance_task
    from pointatlas_executors.dask_executor import DaskExecutor

    items = [i for i in range(202) if i != 2][:200]   # item 2 fails on purpose
    out = {}
    for name, tpt in (("executor_map_batched", 4), ("executor_map_one_task_per_item", 200)):
        ex = DaskExecutor(scheduler_address=address, tasks_per_thread=tpt)
        ex.start()
        walls = []
        with using_executor(ex):
            for _ in range(repeats):
                t0 = time.perf_counter()
                r = ex.map(conformance_task, items, shared=0, desc="trivial")
                walls.append(time.perf_counter() - t0)
                assert r == items
        out[name] = {"wall_s": float(np.median(walls)), "per_item_s": float(np.median(walls)) / 200,
                     "walls": walls}
    from distributed import Client

    with Client(address) as client:
        walls = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            fs = client.map(conformance_task, [0] * 200, items, pure=False)
            r = client.gather(fs)
            walls.append(time.perf_counter() - t0)
            assert r == items
        out["raw_client_map"] = {"wall_s": float(np.median(walls)),
                                 "per_item_s": float(np.median(walls)) / 200, "walls": walls}
    return out


def task_stream_stats(records: list) -> dict:
    """Mean/total compute seconds of the tasks of each map (key prefix = map's desc)."""
    by = defaultdict(list)
    for r in records:
        key = str(r.get("key", ""))
        desc = key.rsplit("-", 2)[0] if key.count("-") >= 2 else key
        comp = sum(s["stop"] - s["start"] for s in r.get("startstops", ())
                   if s.get("action") == "compute")
        by[desc].append(comp)
    return {d: {"n_tasks": len(v), "mean_s": float(np.mean(v)), "max_s": float(np.max(v)),
                "sum_s": float(np.sum(v))} for d, v in by.items()}


def child(args) -> dict:
    import pointatlas_atlas.atlas as atlas_mod
    import pointatlas_atlas.orientation as orientation_mod
    from pointatlas.executor import SerialExecutor, using_executor
    from pointatlas_executors.dask_executor import DaskExecutor

    timers = Timers()
    atlas_mod.refine_partition = timers.wrap("refine_partition", atlas_mod.refine_partition)
    atlas_mod.partition_markers = timers.wrap("metis", atlas_mod.partition_markers)
    orientation_mod.orient_atlas = timers.wrap("orient", orientation_mod.orient_atlas)

    class TimedDask(DaskExecutor):
        def map(self, fn, items, **kw):
            t0 = time.perf_counter()
            try:
                return super().map(fn, items, **kw)
            finally:
                if timers.active:
                    name = "map:" + kw.get("desc", "tasks")
                    timers.t[name] += time.perf_counter() - t0
                    timers.n[name] += 1

    n_workers = CONFIGS[args.config]
    res = {"config": args.config, "n_points": args.n, "quadrature_order": args.order,
           "n_workers": n_workers, "threads_per_worker": 1 if n_workers else None,
           "numba_threads_client": int(os.environ.get("NUMBA_NUM_THREADS", "0")) or None}
    import numba
    res["numba_threads_client"] = numba.config.NUMBA_NUM_THREADS
    est = make_atlas(args.order).estimated_bytes(args.n, args.n, 3, 2)
    res["estimated_bytes"] = est
    res["load_average_start"] = os.getloadavg()
    cpu0 = time.process_time()
    print(f"[{args.config}] N={args.n} order={args.order}: estimated atlas memory "
          f"{est / 2**30:.2f} GiB", flush=True)

    cluster = None
    pids = {"client": os.getpid()}
    if n_workers:
        import logging

        from distributed import LocalCluster

        t0 = time.perf_counter()
        cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                               dashboard_address=":0", silence_logs=logging.WARNING,
                               env={"NUMBA_NUM_THREADS": "1"})
        res["cluster_start_s"] = time.perf_counter() - t0

        def new_executor():
            ex = TimedDask(scheduler_address=cluster.scheduler_address)
            ex.start()
            return ex
    else:
        def new_executor():
            return SerialExecutor()

    # warm-up: numba JIT on the client and (dask) on every worker
    t0 = time.perf_counter()
    with using_executor(new_executor()):
        make_atlas(args.order).build(fibonacci_sphere(2000))
    res["warmup_s"] = time.perf_counter() - t0

    P = fibonacci_sphere(args.n)
    ex = new_executor()
    if n_workers:
        client = ex.client()
        pids.update({f"worker{i}": pid for i, (addr, pid) in
                     enumerate(sorted(client.run(os.getpid).items()))})
    sampler = RssSampler(pids)
    sampler.start()
    atlas = make_atlas(args.order)
    atlas._prefetch_embeddings = timers.wrap("map:patch embeddings(total prefetch)",
                                             atlas._prefetch_embeddings)
    ts_records = []
    timers.active = True
    phases = {}
    with using_executor(ex):
        ctx = None
        if n_workers:
            from distributed import get_task_stream

            ctx = get_task_stream(client)
            ctx.__enter__()
        t_all = time.perf_counter()
        t0 = time.perf_counter()
        atlas.partition(P)
        phases["partition"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        atlas.build_charts()
        phases["charts"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        atlas.build_quadrature()
        phases["quadrature"] = time.perf_counter() - t0
        total = time.perf_counter() - t_all
        timers.active = False
        if n_workers:
            ctx.__exit__(None, None, None)
            ts_records = ctx.data
            res["worker_ru_maxrss_bytes"] = {a: int(v) for a, v in
                                             sorted(client.run(worker_maxrss).items())}
    peaks = sampler.stop()
    t = dict(timers.t)
    res["calls"] = dict(timers.n)
    map_emb = t.get("map:patch embeddings", 0.0)
    map_charts = t.get("map:charts", 0.0)
    map_quad = t.get("map:quadrature", 0.0)
    ph = {
        "partition": phases["partition"],
        "partition_metis": t.get("metis", 0.0),
        "partition_embeddings_refine_loop": t.get("refine_partition", 0.0),
        "partition_embeddings_map": map_emb,
        "partition_rest_pu_kdtree": phases["partition"] - t.get("metis", 0.0)
        - t.get("refine_partition", 0.0),
        "charts": phases["charts"],
        "charts_map": map_charts,
        "quadrature": phases["quadrature"],
        "quadrature_orient": t.get("orient", 0.0),
        "quadrature_map": (map_quad if n_workers else phases["quadrature"] - t.get("orient", 0.0)),
        "total": total,
    }
    ph["sum_of_maps"] = map_emb + map_charts + map_quad
    ph["client_only"] = total - ph["sum_of_maps"] if n_workers else None
    res["phases_s"] = ph
    if n_workers:
        s = ph["client_only"] / total
        res["serial_fraction"] = s
        res["amdahl_limit"] = 1 / s
    res["task_stream"] = task_stream_stats(ts_records) if ts_records else None

    qp = atlas.quadrature_points()
    area = float(np.sum(qp.weights))
    K = float(atlas.integrate(lambda q: q.geometry["gaussian_curvature"]))
    res.update(area=area, total_gaussian_curvature=K,
               rel_err_area=abs(area - FOUR_PI) / FOUR_PI,
               rel_err_total_K=abs(K - FOUR_PI) / FOUR_PI,
               n_patches=len(atlas.charts_), n_quadrature_points=int(len(qp.weights)),
               max_refinement_depth=int(np.max(atlas.patch_depth_)) if len(atlas.patch_depth_)
               else 0)
    if args.dump:
        np.savez(args.dump, labels=atlas.labels_, weights=qp.weights,
                 H=qp.geometry["mean_curvature"], K=qp.geometry["gaussian_curvature"])
    del qp

    if n_workers:
        res["task_overhead"] = task_overhead(cluster.scheduler_address)
        ex.close()
        cluster.close()
    res["client_ru_maxrss_bytes"] = worker_maxrss()
    res["client_vmhwm_bytes"] = vm_hwm_bytes()
    res["psutil_peak_rss_bytes"] = peaks
    res["load_average_end"] = os.getloadavg()
    res["client_cpu_s_whole_process"] = time.process_time() - cpu0
    return res


# -- driver --------------------------------------------------------------------------------
def gib(b):
    return "-" if b is None else f"{b / 2**30:.2f}"


def compare(a_path, b_path) -> float:
    a, b = np.load(a_path), np.load(b_path)
    worst = 0.0
    for k in a.files:
        x, y = a[k].astype(float), b[k].astype(float)
        if x.shape != y.shape:
            return float("inf")
        d = np.abs(x - y) / np.maximum(np.abs(x), 1e-300)
        worst = max(worst, float(np.max(d)) if d.size else 0.0)
    return worst


def table(entries: dict) -> str:
    cols = ["run", "partition", "metis", "emb.loop", "emb.map", "charts", "charts map",
            "quad", "quad map", "orient", "total", "client-only", "s", "1/s", "area relerr",
            "∫K relerr", "client peak GiB", "worker peak GiB"]
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for key, r in entries.items():
        p = r["phases_s"]
        wk = r.get("worker_ru_maxrss_bytes")
        wk = ", ".join(gib(v) for v in wk.values()) if wk else "-"
        cpeak = max(r["client_ru_maxrss_bytes"], r["client_vmhwm_bytes"])
        row = [key, p["partition"], p["partition_metis"], p["partition_embeddings_refine_loop"],
               p["partition_embeddings_map"] if r["n_workers"] else None, p["charts"],
               p["charts_map"] if r["n_workers"] else None, p["quadrature"],
               p["quadrature_map"], p["quadrature_orient"], p["total"], p["client_only"],
               r.get("serial_fraction"), r.get("amdahl_limit")]
        cells = ["-" if v is None else (v if isinstance(v, str) else f"{v:.2f}") for v in row]
        cells += [f"{r['rel_err_area']:.2e}", f"{r['rel_err_total_K']:.2e}", gib(cpeak), wk]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def driver(args):
    out = Path(args.json)
    data = json.loads(out.read_text()) if out.exists() else {"runs": {}, "comparisons": {}}
    tmp = Path(tempfile.mkdtemp(prefix="bench_dask_atlas_"))
    dumps = {}
    for cfg in args.configs:
        key = f"N{args.n}_q{args.order}_{cfg}"
        rj, dump = tmp / f"{key}.json", tmp / f"{key}.npz"
        cmd = [sys.executable, __file__, "--config", cfg, "--n", str(args.n), "--order",
               str(args.order), "--child-json", str(rj), "--dump", str(dump)]
        print("$", " ".join(cmd), flush=True)
        t0 = time.perf_counter()
        p = subprocess.run(cmd)
        wall = time.perf_counter() - t0
        if p.returncode != 0:
            print(f"{key}: failed (exit {p.returncode})", flush=True)
            data["runs"][key] = {"failed": p.returncode, "process_wall_s": wall}
            continue
        r = json.loads(rj.read_text())
        r["process_wall_s"] = wall
        data["runs"][key] = r
        dumps[cfg] = dump
        out.write_text(json.dumps(data, indent=1))
    ref = "local" if "local" in dumps else ("dask1" if "dask1" in dumps else None)
    for cfg, path in dumps.items():
        if ref and cfg != ref:
            d = compare(dumps[ref], path)
            data["comparisons"][f"N{args.n}_q{args.order}_{cfg}_vs_{ref}"] = d
            print(f"largest relative difference {cfg} vs {ref} (labels, weights, H, K): {d:.3e}")
    base = data["runs"].get(f"N{args.n}_q{args.order}_dask1", {})
    two = data["runs"].get(f"N{args.n}_q{args.order}_dask2", {})
    if "phases_s" in base and "phases_s" in two:
        sp = {ph: base["phases_s"][ph] / two["phases_s"][ph]
              for ph in ("partition", "charts", "quadrature", "total", "charts_map",
                         "quadrature_map", "partition_embeddings_map")
              if two["phases_s"][ph]}
        data.setdefault("speedup_1_to_2_workers", {})[f"N{args.n}_q{args.order}"] = sp
        print("speed-up 1 -> 2 workers:", {k: round(v, 3) for k, v in sp.items()})
    out.write_text(json.dumps(data, indent=1))
    ok = {k: v for k, v in data["runs"].items() if "phases_s" in v}
    print(table(ok))
    for k, v in ok.items():
        if v.get("task_overhead"):
            print(k, "per-item overhead (s):",
                  {n: round(o["per_item_s"], 5) for n, o in v["task_overhead"].items()})
        if v.get("task_stream"):
            print(k, "task stream:", {d: (s["n_tasks"], round(s["mean_s"], 3))
                                      for d, s in v["task_stream"].items()})
    print("wrote", out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="\n".join(__doc__.splitlines()[1:]))
    ap.add_argument("--n", type=int, default=100_000, help="points on the sphere")
    ap.add_argument("--order", type=int, default=6, help="quadrature order (default 6)")
    ap.add_argument("--configs", nargs="+", default=list(CONFIGS), choices=list(CONFIGS),
                    help="driver: configurations to run, each in a fresh process")
    ap.add_argument("--config", choices=list(CONFIGS), help="child: run this one here")
    ap.add_argument("--child-json", help="child: write the result here")
    ap.add_argument("--dump", help="child: save labels/weights/H/K (npz) for the comparison")
    ap.add_argument("--json", default=str(DEFAULT_JSON), help="driver: results JSON (updated)")
    args = ap.parse_args(argv)
    if args.config:
        r = child(args)
        Path(args.child_json).write_text(json.dumps(r, indent=1, default=float))
    else:
        driver(args)


if __name__ == "__main__":
    main()
