"""Compare embedders on one point set, before and after the affine isometric correction.

Reproduces thesis Table 1 (L150-165, L2085: stress E_S of the quarter truncated sphere,
k = 12, before and after AIC) and Fig. 2-3 (swiss roll embeddings and intrinsic-dimension
curves, L63-125, L1840-1880).

What carries over from Table 1: the raw E_S of PCA and Isomap and every E_S after AIC are
invariant to the units of the points (E_S is dimensionless) and grow ~ N; the raw E_S of
LLE/MLLE is dominated by the mismatch between their unit-covariance output (thesis L1873)
and the size of the point set, which the thesis does not state, and so is every
``aic_gain`` of LLE/MLLE. ``aic_scale`` (the scale AIC applied) shows that mismatch, and
``aic_vs_pca_*`` compares with Table 1 without it.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

UNITLESS = "1"
#: thesis Table 1 (L150-165, L2085): stress E_S of the quarter truncated sphere, k = 12, raw/AIC
THESIS_TABLE1 = {"pca": (69.1, 45.1), "isomap": (25.9, 11.7), "lle": (30.6e4, 96.5),
                 "mlle": (26.8e4, 6.22)}
THESIS_SOURCE = "Millan 2012 thesis, Table 1 (L150-165, L2085)"


def _attrs(long_name: str, units: str = UNITLESS) -> dict:
    return {"long_name": long_name, "units": units}


class EmbeddingComparison:
    """Embed one point set with several embedders; stress before/after AIC; dimension curves."""

    description: ClassVar[str] = (
        "Embed one point set with several embedders; stress before/after AIC; dimension curves."
    )

    @dataclass
    class Config:
        #: embedder plugin names to compare
        embedders: list[str] = field(default_factory=lambda: ["pca", "isomap", "lle", "mlle"])
        #: neighbours k of every neighbourhood-based embedder and of the stress (thesis: 12)
        n_neighbors: int = 12
        n_components: int = 2
        #: also apply the affine isometric correction to each embedding (stage 'aic')
        aic: bool = True
        #: compute intrinsic-dimension curves (correlation dimension, local PCA, reconstruction)
        dimension_curves: bool = False
        #: neighbours of the local PCA windows of the dimension curves
        local_pca_window: int = 20

    def __init__(self, *, embedders=None, n_neighbors: int = 12, n_components: int = 2,
                 aic: bool = True, dimension_curves: bool = False, local_pca_window: int = 20):
        self.embedders = embedders
        self.n_neighbors = n_neighbors
        self.n_components = n_components
        self.aic = aic
        self.dimension_curves = dimension_curves
        self.local_pca_window = local_pca_window

    def _embedder(self, ctx, name: str):
        from pointatlas import load_plugin

        fields = {f.name for f in dataclasses.fields(load_plugin("embedders", name).Config)}
        wanted = {"n_neighbors": self.n_neighbors, "n_components": self.n_components, "aic": False}
        return ctx.make("embedder", name, **{k: v for k, v in wanted.items() if k in fields})

    def run(self, ctx):
        import xarray as xr
        from pointatlas_embedders.aic import affine_isometric_correction
        from pointatlas_embedders.geodesics import geodesic_neighbors
        from pointatlas_embedders.neighbor_graph import connected_neighbor_graph
        from pointatlas_embedders.quality import stress_on_pairs, trustworthiness

        from pointatlas.errors import ConfigError

        from .embedding import check_embedding_memory

        names = list(self.embedders or self.Config().embedders)
        if not names:
            raise ConfigError("study.embedders is empty: list at least one embedder, e.g. [pca,isomap].")
        with ctx.timed("source"):
            cloud = ctx.plugin("source").load(ctx.rng("source"))
        X = cloud.points
        for name in names:  # refuse a dense embedder too large for memory before any work
            check_embedding_memory(self._embedder(ctx, name), name, len(X), X.shape[1])
        with ctx.timed("geodesics"):
            pairs = geodesic_neighbors(connected_neighbor_graph(X, self.n_neighbors), self.n_neighbors)
        stages = ["raw", "aic"] if self.aic else ["raw"]
        shape = (len(names), len(stages))
        E_S, trust = np.full(shape, np.nan), np.full(shape, np.nan)
        Y_all = np.full((len(names), len(stages), len(X), self.n_components), np.nan)
        scale = np.full(len(names), np.nan)
        seconds = np.zeros(len(names))
        for i, name in enumerate(ctx.progress(names, desc="embedders")):
            with ctx.timed(f"embed_{name}"):
                Y = np.asarray(self._embedder(ctx, name).fit_transform(X))
            seconds[i] = ctx.timings[f"embed_{name}"]
            Y_all[i, 0] = Y
            if self.aic:
                res = affine_isometric_correction(Y, neighbors=pairs)
                Y_all[i, 1] = res.embedding
                scale[i] = float(np.prod(np.linalg.eigvalsh(res.matrix))) ** (1.0 / self.n_components)
            for j in range(len(stages)):
                E_S[i, j] = stress_on_pairs(Y_all[i, j], *pairs)
                trust[i, j] = trustworthiness(Y_all[i, j], X, n_neighbors=self.n_neighbors)
            ctx.log.info("%s: stress %s", name, ", ".join(f"{s} {v:.4g}" for s, v in zip(stages, E_S[i])))
        coords = {
            "embedder": ("embedder", names, _attrs("embedder plugin")),
            "stage": ("stage", stages, _attrs("raw embedding or after affine isometric correction")),
            "point": ("point", np.arange(len(X)), _attrs("point index")),
            "latent": ("latent", np.arange(self.n_components), _attrs("embedding axis")),
            "dim": ("dim", np.arange(X.shape[1]), _attrs("ambient axis")),
        }
        data = {
            "points": (("point", "dim"), X, _attrs("input point coordinates")),
            "embedding": (("embedder", "stage", "point", "latent"), Y_all, _attrs("embedded coordinates")),
            "stress": (("embedder", "stage"), E_S,
                       _attrs(f"stress E_S over the {self.n_neighbors} geodesic nearest neighbours")),
            "trustworthiness": (("embedder", "stage"), trust, _attrs("trustworthiness")),
            "embedding_time": (("embedder",), seconds, _attrs("wall time of the embedding", "s")),
            "n_points": ((), len(X), _attrs("number of points")),
        }
        table1 = ctx.plugin_name("source") == "quarter_truncated_sphere"
        if self.aic:
            data["aic_scale"] = (("embedder",), scale, _attrs(
                "geometric mean of the eigenvalues of the AIC matrix A (1: raw metric kept)"))
            for i, name in enumerate(names):
                attrs = _attrs(f"stress of {name} before / after AIC")
                if table1 and name in THESIS_TABLE1:
                    raw, aic = THESIS_TABLE1[name]
                    attrs.update(reference=raw / aic, reference_source=THESIS_SOURCE)
                data[f"aic_gain_{name}"] = ((), E_S[i, 0] / E_S[i, 1], attrs)
            if "pca" in names:
                # scale-free comparison with Table 1: neither the unstated output scale of
                # LLE/MLLE (which sets the raw column, hence the gains) nor N enters much
                pca = E_S[names.index("pca"), 1]
                for i, name in enumerate(names):
                    if name == "pca":
                        continue
                    attrs = _attrs(f"stress of {name} after AIC / stress of pca after AIC")
                    if table1 and name in THESIS_TABLE1:
                        attrs.update(reference=THESIS_TABLE1[name][1] / THESIS_TABLE1["pca"][1],
                                     reference_source=THESIS_SOURCE)
                    data[f"aic_vs_pca_{name}"] = ((), E_S[i, 1] / pca, attrs)
            if table1:
                ref = np.array([THESIS_TABLE1.get(n, (np.nan, np.nan)) for n in names])
                data["stress_reference"] = (("embedder", "stage"), ref[:, :len(stages)], {
                    **_attrs("published stress E_S (sampling differs: compare ratios)"),
                    "reference_source": THESIS_SOURCE})
        ds = xr.Dataset(data, coords=coords, attrs={"title": f"embeddings of {cloud.name}"})
        if self.dimension_curves:
            ds = ds.merge(self._dimension_curves(X))
        return ds

    def _dimension_curves(self, X):
        import xarray as xr
        from pointatlas_embedders.intrinsic_dimension import (
            correlation_dimension, local_pca_residual_variance, pca_reconstruction_error)

        scales, C, d_corr = correlation_dimension(X)
        dims, mean, pct = local_pca_residual_variance(X, n_window=self.local_pca_window)
        rdims, rmean, rpct = pca_reconstruction_error(X)
        return xr.Dataset(
            {
                "correlation_sum": (("scale",), C, _attrs("correlation sum C(eps)")),
                "correlation_dimension": (("scale",), d_corr, _attrs("d log C / d log eps")),
                "local_pca_residual": (("d",), mean, _attrs("1 - cumulative explained variance of local PCA, mean")),
                "local_pca_residual_percentile": (("percentile", "d"), pct,
                                                  _attrs("1 - cumulative explained variance of local PCA, percentiles")),
                "reconstruction_error": (("d",), rmean, _attrs("PCA reconstruction error (thesis Eq. 1), mean")),
                "reconstruction_error_percentile": (("percentile", "d"), rpct,
                                                    _attrs("PCA reconstruction error, percentiles")),
            },
            coords={
                "scale": ("scale", scales, _attrs("radius eps", "length units of the points")),
                "d": ("d", dims, _attrs("candidate intrinsic dimension")),
                "percentile": ("percentile", [25, 75], _attrs("percentile across points", "percent")),
            },
        )

    @staticmethod
    def report_figures(ds):
        import matplotlib.pyplot as plt

        figures = []
        names, stages = list(ds["embedder"].values), list(ds["stage"].values)
        fig, axes = plt.subplots(len(stages), len(names), figsize=(2.6 * len(names), 2.6 * len(stages)),
                                 squeeze=False)
        color = ds["points"].values[:, -1]
        for j, stage in enumerate(stages):
            for i, name in enumerate(names):
                Y = ds["embedding"].sel(embedder=name, stage=stage).values
                ax = axes[j, i]
                ax.scatter(Y[:, 0], Y[:, 1] if Y.shape[1] > 1 else 0 * Y[:, 0], c=color, s=2)
                ax.set_title(f"{name} {stage}\nE_S={float(ds['stress'].sel(embedder=name, stage=stage)):.3g}",
                             fontsize=8)
                ax.set_xticks([])
                ax.set_yticks([])
                ax.set_aspect("equal", adjustable="datalim")
        fig.tight_layout()
        figures.append(("Embeddings (colour: last ambient coordinate)", fig))
        if "correlation_dimension" in ds:
            fig, axes = plt.subplots(1, 3, figsize=(12, 3.4))
            axes[0].semilogx(ds["scale"], ds["correlation_dimension"])
            axes[0].set(xlabel="scale eps", ylabel="correlation dimension")
            for ax, var in ((axes[1], "local_pca_residual"), (axes[2], "reconstruction_error")):
                pct = ds[f"{var}_percentile"].values
                ax.semilogy(ds["d"], ds[var], "o-")
                ax.fill_between(ds["d"], np.maximum(pct[0], 1e-16), np.maximum(pct[1], 1e-16), alpha=0.3)
                ax.set(xlabel="d", ylabel=ds[var].attrs["long_name"][:40])
            fig.tight_layout()
            figures.append(("Intrinsic dimension (thesis Fig. 3)", fig))
        return figures
