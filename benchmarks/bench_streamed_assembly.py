"""The shell energy's tangent on a large hemisphere, streamed: local vs Dask 1 and 2 workers.

At 2·10⁵ points the kit's quadrature with its basis would need ~70 GiB
(``bench_dask_assembly.py --estimate-only``), so the model is built with
``build_surface_model(keep_basis=False)`` (charts and Gauss points only) and K of the linear
Kirchhoff–Love energy at U = 0 is assembled by :func:`pointatlas_kit.streamed_tangent.
streamed_tangent`: chart groups rebuild their basis, assemble and drop it; the client sums the
parts; K is kept as its block upper triangle (``upper=True``: K is symmetric, and the parts
and K then need half the memory; the full K of 2·10⁵ points is 8 GB in CSR). The cloud is
the quarter hemisphere of ``experiment=shell_hemisphere`` (radius 10,
closed pole, E = 6.825e7, ν = 0.3, h = 0.04), with its atlas settings (embedder pca).

Each configuration runs in a fresh child process (``local``: this process with numba's
threads; ``dask1``/``dask2``: a LocalCluster of 1|2 worker processes × 1 thread,
NUMBA_NUM_THREADS=1, started by the child; a ``--warmup-n`` run compiles numba first on the
client and the workers). Reported per configuration: wall time of each stage (boundary +
partition: serial on the client; charts, quadrature: patch tasks; tangent: group tasks; the
client's sum of the parts: serial), the tasks' compute time (Dask task stream) and the
per-task overhead (wall × threads − Σ compute) / tasks, the serial fraction (partition +
sum) / total, peak RSS of the client and each worker (psutil, every 0.1 s), K's size and a
fingerprint (‖U v‖ of the stored triangle U for a fixed v, compared between configurations).

Usage:
  python benchmarks/bench_streamed_assembly.py --n 200000 --configs local dask1 dask2
Writes/updates benchmarks/results/streamed_assembly.json (one entry per N and config).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from bench_dask_assembly import TreeSampler, gib  # noqa: E402

RESULTS = Path(__file__).parent / "results"
DEFAULT_JSON = RESULTS / "streamed_assembly.json"


def build_and_assemble(n: int, group_points: int) -> dict:
    """Model (no basis kept) and streamed K of the quarter hemisphere of n points."""
    import pointatlas
    from pointatlas_atlas.atlas import AtlasSettings
    from pointatlas_kit import streamed_tangent as st
    from pointatlas_kit.fields import FieldLayout
    from pointatlas_kit.surface_model import (atlas_factories, build_surface_model,
                                              check_every_point_integrated)
    from pointatlas_physics.kirchhoff_love.shell_energy import DISPLACEMENT, ShellEnergy

    times = {}
    summed = {}
    original_sum = st.sum_block_parts

    def timed_sum(*a, **kw):
        t0 = time.perf_counter()
        out = original_sum(*a, **kw)
        summed["s"] = time.perf_counter() - t0
        return out

    st.sum_block_parts = timed_sum
    source = pointatlas.load_plugin("sources", "hemisphere")(
        n_points=n, model="quarter", hole_angle_deg=0.0)
    cloud = source.load(np.random.default_rng(0))
    s = AtlasSettings()
    t0 = time.perf_counter()
    m = build_surface_model(cloud, s, order=2, block=3, keep_basis=False, solve=False,
                            **atlas_factories(None, s))
    times["model_wall"] = time.perf_counter() - t0
    times.update({f"model_{k}": v for k, v in m.times.items()})
    layout = FieldLayout([DISPLACEMENT], m.nodes.shape[0])
    t0 = time.perf_counter()
    K = st.streamed_tangent(m.atlas, layout, [ShellEnergy(6.825e7, 0.3, 0.04)],
                            group_points=group_points, upper=True)
    times["tangent_wall"] = time.perf_counter() - t0
    times["sum_wall"] = summed["s"]
    touched = np.zeros(layout.n_nodes, bool)
    touched[np.flatnonzero(np.diff(K.indptr))] = True
    real = np.arange(layout.n_nodes) < len(m.points)
    check_every_point_integrated(touched, real)
    v = np.random.default_rng(7).normal(size=K.shape[0])
    return dict(times=times, n_nodes=int(layout.n_nodes), n_dofs=int(K.shape[0]),
                nnz=int(K.nnz), block_nnz=int(len(K.indices)),
                gauss_points=int(sum(len(c.weights) for c in m.atlas.quadrature_)),
                n_charts=len(m.atlas.charts_),
                n_groups=len(st.chart_groups(m.atlas.quadrature_, group_points)),
                Kv_norm=float(np.linalg.norm(K @ v)),
                diag_sum=float(K.diagonal().sum()))


def child(args) -> None:
    record = {"config": args.config, "n_points": args.n, "load_average_start": os.getloadavg()}
    cluster = executor = None
    if args.config != "local":
        import logging

        from distributed import LocalCluster
        from pointatlas_executors.dask_executor import DaskExecutor

        k = int(args.config[-1])
        cluster = LocalCluster(n_workers=k, threads_per_worker=1, processes=True,
                               dashboard_address=":0", silence_logs=logging.WARNING,
                               env={"NUMBA_NUM_THREADS": "1"})
        executor = DaskExecutor(scheduler_address=cluster.scheduler_address)
    from contextlib import nullcontext

    from pointatlas.executor import using_executor

    scope = using_executor(executor) if executor is not None else nullcontext()
    with scope:
        if args.warmup_n:
            t0 = time.perf_counter()
            build_and_assemble(args.warmup_n, args.group_points)
            record["warmup"] = {"n_points": args.warmup_n, "wall_s": time.perf_counter() - t0}
        sampler = TreeSampler()
        sampler.start()
        stream = None
        t0 = time.perf_counter()
        if executor is not None:
            from distributed import get_task_stream

            with get_task_stream(executor.client()) as ts:
                out = build_and_assemble(args.n, args.group_points)
            stream = ts.data
        else:
            out = build_and_assemble(args.n, args.group_points)
        record["wall_s"] = time.perf_counter() - t0
        sampler.stop()
    record.update(out)
    if stream is not None:
        per_prefix: dict = {}
        for task in stream:
            prefix = str(task["key"]).split("-")[0]
            c = sum(ss["stop"] - ss["start"] for ss in task["startstops"]
                    if ss["action"] == "compute")
            d = per_prefix.setdefault(prefix, {"tasks": 0, "compute_s": 0.0})
            d["tasks"] += 1
            d["compute_s"] += c
        record["task_stream"] = per_prefix
        tangent = [v for k, v in per_prefix.items() if k.startswith("streamed tangent")]
        if tangent:
            t = tangent[0]
            threads = int(args.config[-1])
            map_wall = out["times"]["tangent_wall"] - out["times"]["sum_wall"]
            record["tangent_tasks"] = t["tasks"]
            record["tangent_task_overhead_s"] = (map_wall * threads - t["compute_s"]) / t["tasks"]
    T = out["times"]
    serial = T.get("model_boundary", 0) + T.get("model_partition", 0) + T["sum_wall"]
    record["serial_s"] = serial
    record["serial_fraction"] = serial / (T["model_wall"] + T["tangent_wall"])
    me = os.getpid()
    record["peak_rss_bytes"] = {("client" if pid == me else f"pid{pid}"): v
                                for pid, v in sampler.peak.items()}
    record["peak_rss_cmd"] = {("client" if pid == me else f"pid{pid}"): sampler.names.get(pid)
                              for pid in sampler.peak}
    record["load_average_end"] = os.getloadavg()
    if cluster is not None:
        executor.close()
        cluster.close()
    Path(args.child_json).write_text(json.dumps(record, indent=1))


def driver(args) -> None:
    results = json.loads(args.json.read_text()) if args.json.exists() else {}
    rows = []
    for config in args.configs:
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "child.json"
            cmd = [sys.executable, __file__, "--child", "--config", config, "--n", str(args.n),
                   "--warmup-n", str(args.warmup_n), "--group-points", str(args.group_points),
                   "--child-json", str(out)]
            t0 = time.perf_counter()
            r = subprocess.run(cmd, env={**os.environ, "PYTHONWARNINGS": "ignore"})
            wall = time.perf_counter() - t0
            if r.returncode != 0 or not out.exists():
                print(f"{config}: child failed (exit {r.returncode})", flush=True)
                continue
            rec = json.loads(out.read_text())
        rec["process_wall_s"] = wall
        results.setdefault(str(args.n), {})[config] = rec
        rows.append(rec)
        T = rec["times"]
        peaks = rec["peak_rss_bytes"]
        workers = [gib(v) for k, v in peaks.items() if k != "client"]
        print(f"{config}: model {T['model_wall']:.1f} s (partition {T.get('model_partition', 0):.1f},"
              f" charts {T.get('model_charts', 0):.1f}, quadrature {T.get('model_quadrature', 0):.1f})"
              f", tangent {T['tangent_wall']:.1f} s (client sum {T['sum_wall']:.1f} s), "
              f"serial fraction {rec['serial_fraction']:.3f}, per-task overhead "
              f"{rec.get('tangent_task_overhead_s', float('nan')):.3f} s, client peak "
              f"{gib(peaks['client'])} GiB, worker/other peaks {workers} GiB, K nnz "
              f"{rec['nnz']:.3e}, |Kv| {rec['Kv_norm']:.12e}", flush=True)
    if len(rows) > 1:
        ref = rows[0]["Kv_norm"]
        for rec in rows[1:]:
            print(f"{rec['config']} vs {rows[0]['config']}: |Kv| relative difference "
                  f"{abs(rec['Kv_norm'] - ref) / ref:.2e}")
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(results, indent=1))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--n", type=int, default=20000)
    p.add_argument("--configs", nargs="+", default=["local", "dask1", "dask2"],
                   choices=["local", "dask1", "dask2"])
    p.add_argument("--warmup-n", type=int, default=600)
    p.add_argument("--group-points", type=int, default=None)
    p.add_argument("--json", type=Path, default=DEFAULT_JSON)
    p.add_argument("--child", action="store_true")
    p.add_argument("--config", default="local")
    p.add_argument("--child-json")
    args = p.parse_args(argv)
    if args.group_points is None:
        from pointatlas_kit.streamed_tangent import GROUP_POINTS

        args.group_points = GROUP_POINTS
    (child if args.child else driver)(args)


if __name__ == "__main__":
    main()
