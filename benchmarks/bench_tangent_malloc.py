"""One part of the shell tangent with glibc's default malloc and with Dask's worker setting.

Dask's nanny starts every worker with MALLOC_TRIM_THRESHOLD_=65536 (freed memory goes back
to the OS at once). A kernel that allocates arrays per batch then gets fresh pages, zeroed
by the kernel, for every batch. This times the same part of the tangent (the first thread
part of the full hemisphere, ``n`` points, numba warm, BLAS at one thread) in a child
process with each setting: best of ``repeats``.

Usage: .venv/bin/python benchmarks/bench_tangent_malloc.py [n_points] [repeats]
Writes benchmarks/results/tangent_malloc.json.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).parent
SETTINGS = {"glibc default": None, "dask worker (MALLOC_TRIM_THRESHOLD_=65536)": "65536"}


def child(n_points: int, repeats: int) -> float:
    import numpy as np

    sys.path.insert(0, str(HERE))
    from bench_shell_hemisphere import hemisphere_model, settings
    from pointatlas_kit.assembler import tangent_part
    from pointatlas_physics.kirchhoff_love.nonlinear import shell_assembler

    model, _ = hemisphere_model(n_points, settings("direct"))
    assembler = shell_assembler(model.quadrature, model.material)
    U = np.zeros((assembler.layout.n_nodes, 3))
    assembler.tangent(U)                        # compile and build the plan
    b0, b1 = (int(x) for x in assembler.q.assembly_plan().thread_bounds[0])
    best = np.inf
    for _ in range(repeats):
        t = time.perf_counter()
        tangent_part(assembler, (U, b0, b1))
        best = min(best, time.perf_counter() - t)
    return best


def main(n_points: int, repeats: int) -> None:
    out = {"n_points": n_points, "repeats": repeats, "seconds": {}}
    for name, trim in SETTINGS.items():
        env = dict(os.environ)
        env.pop("MALLOC_TRIM_THRESHOLD_", None)
        if trim is not None:
            env["MALLOC_TRIM_THRESHOLD_"] = trim
        res = subprocess.run([sys.executable, __file__, "--child", str(n_points), str(repeats)],
                             env=env, capture_output=True, text=True, check=True)
        out["seconds"][name] = float(res.stdout.strip().splitlines()[-1])
        print(f"{name:45s} {out['seconds'][name]:7.3f} s (one tangent part, best of {repeats})")
    path = HERE / "results" / "tangent_malloc.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        print(child(int(sys.argv[2]), int(sys.argv[3])))
    else:
        main(int(sys.argv[1]) if len(sys.argv) > 1 else 1500,
             int(sys.argv[2]) if len(sys.argv) > 2 else 3)
