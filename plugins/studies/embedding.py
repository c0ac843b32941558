"""Embed a point set in low dimension and measure how isometric the embedding is."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np


def parameter_correlation(embedding: np.ndarray, parameters: np.ndarray) -> float:
    """How well the embedding recovers known intrinsic coordinates, in [0, 1].

    The mean over intrinsic coordinates of the best absolute Pearson correlation with any
    embedding axis after an optimal linear map (R of a least-squares fit), so that a
    rotation or reflection of the embedding does not matter.
    """
    Y = np.column_stack([embedding - embedding.mean(0), np.ones(len(embedding))])
    scores = []
    for target in np.atleast_2d(parameters.T):
        coef, *_ = np.linalg.lstsq(Y, target, rcond=None)
        fit = Y @ coef
        scores.append(abs(np.corrcoef(fit, target)[0, 1]))
    return float(np.mean(scores))


def neighbor_requirements(embedder, stress_neighbors: int,
                          trustworthiness_neighbors: int) -> dict[str, tuple[int, int, str]]:
    """What each neighbourhood setting of the embedding study needs of the number of points.

    Returns {override key: (value k, fewest points, rule)}: the embedder's k-NN graph
    (``embedder.n_neighbors``, if it has an integer one) needs k + 1 points, the stress E_S
    k + 1 and the trustworthiness 2k + 1 (:func:`pointatlas_embedders.quality.min_points`).
    """
    from pointatlas_embedders.quality import min_points

    needs = {}
    k = getattr(embedder, "n_neighbors", None)
    if isinstance(k, (int, np.integer)) and not isinstance(k, bool):
        needs["embedder.n_neighbors"] = (int(k), int(k) + 1, "n_neighbors + 1")
    needs["study.stress_neighbors"] = (stress_neighbors, min_points("stress", stress_neighbors),
                                       "stress_neighbors + 1")
    needs["study.trustworthiness_neighbors"] = (
        trustworthiness_neighbors, min_points("trustworthiness", trustworthiness_neighbors),
        "2 trustworthiness_neighbors + 1")
    return needs


def check_enough_points(n_points: int, embedder_name: str, needs: dict) -> None:
    """Refuse, before any work, a point set too small for the study's neighbourhoods.

    One :class:`InputError` line: the number of points, what every setting needs, and the
    fix (more points, or the largest values of the settings that fit ``n_points``).
    """
    from pointatlas.errors import InputError

    short = {key: v for key, v in needs.items() if n_points < v[1]}
    if not short:
        return
    most = max(v[1] for v in needs.values())
    parts = ", ".join(f"{key}={k} needs {need} ({rule})" for key, (k, need, rule) in short.items())
    largest = {"study.trustworthiness_neighbors": (n_points - 1) // 2}
    fits = ", ".join(f"{key}={largest.get(key, n_points - 1)}" for key in short)
    fix = (f"lower them to fit {n_points} points ({fits})" if n_points >= 3
           else "no neighbourhood fits fewer than 3 points")
    raise InputError(
        f"{n_points} points are too few for the embedding study with {embedder_name}: {parts}. "
        f"Give at least {most} points (raise source.n_points, or use a file with more "
        f"points), or {fix}.")


def check_embedding_memory(embedder, name: str, n_points: int, ambient_dim: int) -> None:
    """Refuse, before any work, an embedding whose memory (the embedder's ``estimated_bytes``,
    if it has one) does not fit the memory available; the fix names a size that fits."""
    from pointatlas_atlas import memory_estimate as mem

    estimate = getattr(embedder, "estimated_bytes", None)
    if estimate is None:
        return
    needed = int(estimate(n_points, ambient_dim))
    available, _ = mem.available_memory_bytes()
    fitting = n_points  # the suggested size leaves 10 % of the available memory free
    while fitting > 2 and estimate(fitting, ambient_dim) > 0.9 * available:
        fitting = int(fitting * 0.9)
    mem.check_memory(needed, f"{name} on {n_points} points in R^{ambient_dim}",
                     f"Use fewer points (e.g. source.n_points={fitting}) or an embedder whose "
                     "memory grows linearly with the points (pca, nlie, lle).")


class EmbeddingStudy:
    """Embed the source's points with the selected embedder; report stress and trustworthiness."""

    description: ClassVar[str] = (
        "Embed the source's points with the selected embedder; report stress and trustworthiness."
    )

    @dataclass
    class Config:
        #: neighbours k_G over which the stress E_S compares distances (thesis Table 1: 12)
        stress_neighbors: int = 12
        #: neighbours of the trustworthiness measure
        trustworthiness_neighbors: int = 12

    def __init__(self, *, stress_neighbors: int = 12, trustworthiness_neighbors: int = 12):
        self.stress_neighbors = stress_neighbors
        self.trustworthiness_neighbors = trustworthiness_neighbors

    def run(self, ctx):
        import xarray as xr
        from pointatlas_embedders.quality import stress, trustworthiness

        with ctx.timed("source"):
            cloud = ctx.plugin("source").load(ctx.rng("source"))
        embedder = ctx.plugin("embedder")
        check_enough_points(cloud.n_points, ctx.plugin_name("embedder"), neighbor_requirements(
            embedder, self.stress_neighbors, self.trustworthiness_neighbors))
        check_embedding_memory(embedder, ctx.plugin_name("embedder"), cloud.n_points,
                               cloud.ambient_dim)
        ctx.log.info("embedding %d points in R^%d with %s", cloud.n_points, cloud.ambient_dim,
                     ctx.plugin_name("embedder"))
        with ctx.timed("embedding"):
            Y = np.asarray(embedder.fit_transform(cloud.points))
        with ctx.timed("quality"):
            e_s = stress(Y, cloud.points, n_neighbors=self.stress_neighbors)
            trust = trustworthiness(Y, cloud.points, n_neighbors=self.trustworthiness_neighbors)
        ds = xr.Dataset(
            {
                "points": (("point", "dim"), cloud.points,
                           {"long_name": "input point coordinates", "units": "1"}),
                "embedding": (("point", "latent"), Y,
                              {"long_name": "embedded coordinates", "units": "1"}),
                "stress": ((), e_s, {"long_name": "stress E_S of the embedding (thesis Table 1)",
                                     "units": "1"}),
                "trustworthiness": ((), trust, {"long_name": "trustworthiness", "units": "1"}),
                "n_points": ((), cloud.n_points, {"long_name": "number of points", "units": "1"}),
            },
            coords={
                "point": ("point", np.arange(cloud.n_points), {"long_name": "point index", "units": "1"}),
                "dim": ("dim", np.arange(cloud.ambient_dim), {"long_name": "ambient axis", "units": "1"}),
                "latent": ("latent", np.arange(Y.shape[1]), {"long_name": "embedding axis", "units": "1"}),
            },
            attrs={"title": f"{ctx.plugin_name('embedder')} embedding of {cloud.name}"},
        )
        if cloud.parameters is not None:
            P = np.asarray(cloud.parameters).reshape(cloud.n_points, -1)
            ds["parameters"] = (("point", "parameter"), P,
                                {"long_name": "exact intrinsic coordinates", "units": "1"})
            ds = ds.assign_coords(parameter=("parameter", np.arange(P.shape[1]),
                                             {"long_name": "intrinsic coordinate index", "units": "1"}))
            ds["parameter_correlation"] = ((), parameter_correlation(Y, P), {
                "long_name": "correlation of the embedding with the exact intrinsic coordinates",
                "units": "1"})
        return ds

    @staticmethod
    def report_figures(ds):
        """The embedding coloured by the first exact intrinsic coordinate (or point index)."""
        import matplotlib.pyplot as plt

        Y = ds["embedding"].values
        color = ds["parameters"].values[:, 0] if "parameters" in ds else np.arange(len(Y))
        fig, ax = plt.subplots(figsize=(5, 4))
        if Y.shape[1] >= 2:
            sc = ax.scatter(Y[:, 0], Y[:, 1], c=color, s=4, cmap="viridis")
            ax.set_xlabel("embedding axis 0")
            ax.set_ylabel("embedding axis 1")
            ax.set_aspect("equal", adjustable="datalim")
        else:
            sc = ax.scatter(Y[:, 0], np.zeros(len(Y)), c=color, s=4, cmap="viridis")
            ax.set_xlabel("embedding axis 0")
        fig.colorbar(sc, ax=ax, label="intrinsic coordinate 0" if "parameters" in ds else "point")
        ax.set_title(ds.attrs.get("title", "embedding"))
        fig.tight_layout()
        return [("Embedding", fig)]
