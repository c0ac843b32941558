"""Frames to report for a 400-frame 512×512 sequence (issue 20 acceptance: under 3 minutes).

Two runs of ``experiment=metaboly_synthetic`` (4 cycles, 400 frames of 512², the default
noise and drift) from the command line, as a user would:

1. ``synthetic``: the synthetic source renders the frames inside the run;
2. ``video``: the same frames first encoded to an H.264 .mp4 (not timed), then read by
   ``source=frames`` — the path of a user's video.

Each is followed by ``pointatlas-report`` on its run directory. The table gives the wall
time of the run, of the report, and the run's own split by stage (the ``time_*`` variables
of its results: frames, segmentation, descriptors, embedding, parametrisation,
kinematics + hydrodynamics, truth).

Usage: python benchmarks/bench_metaboly.py [out.nc] [--workdir DIR]
Writes benchmarks/results/bench_metaboly.nc by default.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

TARGET = 180.0
BIN = Path(sys.executable).parent


def _run(args, cwd):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    t0 = time.perf_counter()
    out = subprocess.run([str(BIN / args[0]), *args[1:]], cwd=cwd, capture_output=True,
                         text=True, env=env)
    if out.returncode != 0:
        raise SystemExit(out.stderr[-3000:])
    return time.perf_counter() - t0


def _write_video(path: Path) -> float:
    import imageio.v2 as imageio

    import pointatlas

    seq = pointatlas.load_plugin("sources", "synthetic_metaboly")().load(
        np.random.default_rng(0))
    rate = 1.0 / float(np.diff(np.sort(seq.times)).mean())
    with imageio.get_writer(path, format="FFMPEG", fps=rate, codec="libx264", quality=9,
                            macro_block_size=16) as w:
        for f in seq.frames[np.argsort(seq.times)]:
            w.append_data((255 * f).astype(np.uint8))
    return rate


def main(argv=None):
    import xarray as xr

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", nargs="?", default=str(Path(__file__).parent / "results" /
                                                 "bench_metaboly.nc"))
    p.add_argument("--workdir", default=None)
    a = p.parse_args(argv)
    work = Path(a.workdir or tempfile.mkdtemp(prefix="bench_metaboly_"))
    rate = _write_video(work / "cell.mp4")
    cases = {"synthetic": [],
             "video": ["source=frames", f"source.path={work / 'cell.mp4'}",
                       f"source.frame_rate={rate}", "source.pixel_size=0.2"]}
    rows, stages = [], {}
    for name, extra in cases.items():
        out_root = work / name
        run_s = _run(["pointatlas", "experiment=metaboly_synthetic", *extra,
                      f"outputs_root={out_root}"], work)
        run_dir = next(out_root.glob("runs/*/*/results.nc")).parent
        report_s = _run(["pointatlas-report", str(run_dir)], work)
        with xr.open_dataset(run_dir / "results.nc") as ds:
            stages[name] = {k[5:]: float(ds[k]) for k in ds.data_vars if k.startswith("time_")}
        rows.append((name, run_s, report_s, run_s + report_s))
    print(f"{'case':<10}{'run s':>8}{'report s':>10}{'total s':>9}  under 3 min")
    for name, r, rep, tot in rows:
        print(f"{name:<10}{r:>8.1f}{rep:>10.1f}{tot:>9.1f}  {'yes' if tot < TARGET else 'NO'}")
    for name, st in stages.items():
        print(f"{name} stages (s): " + ", ".join(f"{k} {v:.1f}" for k, v in st.items()))
    ds = xr.Dataset({
        "total_seconds": (("case",), [r[3] for r in rows], {"long_name": "run + report wall "
                                                            "time", "units": "s"}),
        "run_seconds": (("case",), [r[1] for r in rows], {"long_name": "run wall time",
                                                          "units": "s"}),
        "report_seconds": (("case",), [r[2] for r in rows], {"long_name": "report wall time",
                                                             "units": "s"})},
        coords={"case": ("case", [r[0] for r in rows], {"long_name": "input", "units": "1"})},
        attrs={"title": "metaboly: 400 frames of 512² to report",
               "stages": repr(stages)})
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(a.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
