"""How much a linear shell figure moves under round-off: the conditioning of K + ρCᵀC.

Builds the model of a linear shell experiment (its source, physics and atlas settings read
from ``experiments/<name>.yaml``; PCA charts as the experiments use), solves it, then solves
again with the stiffness perturbed by symmetric relative noise of size ``eps`` (default
1e-15, i.e. a different order of floating-point sums) and prints the relative change of the
reference displacement. With ``--old PATH`` (a checkout before the physics kit) it also
solves with the old hand-written assembler's K on the same quadrature. With the ghost
springs (1e-10 × mean diag K) and the former augmented-Lagrangian penalty (1e6 × mean diag K)
figures moved by 2.7e-5 (hemisphere) and 6e-6 (plate) under round-off; with the penalty
10² × mean diag K (the default since 2026-12-02) by 1.2e-10 and 5.7e-11.

Usage: .venv/bin/python benchmarks/solve_sensitivity.py shell_plate [--old /tmp/oldtree]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from omegaconf import OmegaConf

import pointatlas
from pointatlas_atlas.settings import AtlasSettings
from pointatlas_kit.surface_model import values_at
from pointatlas_physics.kirchhoff_love.analysis import (assemble_loads, assemble_supports,
                                                         build_model, regularize_ghosts)
from pointatlas_physics.kirchhoff_love.linear import linear_stiffness
from pointatlas_physics.kirchhoff_love.plugin import KirchhoffLove
from pointatlas_solvers.augmented_lagrangian import solve_augmented

ROOT = Path(__file__).resolve().parents[1]


def experiment_model(name: str):
    cfg = OmegaConf.to_container(OmegaConf.load(ROOT / "experiments" / f"{name}.yaml"))
    source = [d["override /source"] for d in cfg["defaults"] if "override /source" in d][0]
    cloud = pointatlas.load_plugin("sources", source)(**cfg.get("source", {})).load(
        np.random.default_rng(0))
    physics = KirchhoffLove(**cfg["physics"])
    s = physics.shell_settings()
    a = AtlasSettings(**{"markers_per_patch": 100, **cfg.get("atlas", {})})

    def make(family, plugin, **kw):
        return lambda: pointatlas.load_plugin(family, plugin)(**kw)
    model = build_model(cloud, s, a, make("embedders", "pca", n_components=2),
                        make("approximants", "lme", gamma=a.gamma_lme, tol=a.tol_lme,
                             outside="flag"),
                        make("approximants", "shepard", gamma=a.gamma_pu, tol=a.tol_pu,
                             outside="flag"))
    study = cfg.get("study", {})
    e = np.asarray(study.get("reference_direction", [0, 0, -1.0]), float)
    return model, s, np.asarray(study.get("reference_point", [0, 0, 0.0]), float), e / np.linalg.norm(e)


def main(name: str, eps: float, old: Path | None) -> None:
    model, s, x, e = experiment_model(name)
    F = assemble_loads(model, s).ravel()
    cons = assemble_supports(model, s)

    def figure(K):
        U = solve_augmented(K, F, cons.matrix, cons.rhs, s.penalty, s.constraint_tol)[0]
        return float(values_at(model.atlas, U.reshape(-1, 3), x[None])[0][0] @ e)

    K = linear_stiffness(model.quadrature, model.material)
    w0 = figure(regularize_ghosts(K, model))
    rng = np.random.default_rng(0)
    Kn = K.copy()
    Kn.data = Kn.data * (1 + eps * rng.standard_normal(Kn.nnz))
    w1 = figure(regularize_ghosts(0.5 * (Kn + Kn.T), model))
    print(f"{name}: reference displacement {w0:.12g} ({model.dof} DOF)")
    print(f"  relative change under {eps:g} relative noise in K: {abs(w1 - w0) / abs(w0):.2e}")
    if old:
        sys.path.insert(0, str(ROOT / "benchmarks"))
        from bench_shell_assembly import load_old

        lin, _, _, convert = load_old(old)
        K_old = lin(convert(model.quadrature), model.material)
        w2 = figure(regularize_ghosts(K_old, model))
        print(f"  old assembler: {w2:.12g}; max |K - K_old| / max |K_old| = "
              f"{abs(K - K_old).max() / abs(K_old).max():.1e}; relative change of the figure "
              f"{abs(w2 - w0) / abs(w0):.2e}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("experiment")
    ap.add_argument("--eps", type=float, default=1e-15)
    ap.add_argument("--old", type=Path, default=None)
    a = ap.parse_args()
    main(a.experiment, a.eps, a.old)
