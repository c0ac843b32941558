"""Area, Willmore energy and total Gaussian curvature of a point-set surface via its atlas.

Thesis §3 (L125–360) and Paper 1 §2.6 (L1085): partition the markers, build one LME chart
per patch, glue with the coarse Shepard partition of unity ψ_κ and integrate
∫_M f ≈ Σ_κ Σ_g w_g J_κ ψ_κ f with f = 1 (area), H² with H = κ1 + κ2 (Willmore energy,
16π on a sphere) and K (total Gaussian curvature, 2πχ by Gauss–Bonnet).
"""
from __future__ import annotations

from typing import ClassVar

import numpy as np
from pointatlas_atlas.settings import AtlasSettings

from pointatlas.stores_config import stores_config

#: exact-reference key -> (metric name, long name)
QUANTITIES = {
    "area": ("area", "surface area ∫_M dA"),
    "willmore_energy": ("willmore_energy", "Willmore energy ∫_M H² dA, H = κ1 + κ2"),
    "total_gaussian_curvature": ("total_gaussian_curvature", "total Gaussian curvature ∫_M K dA"),
}


@stores_config
class SurfaceGeometry:
    """Build the atlas of the source's points; integrate area, H² and K; compare with exact."""

    description: ClassVar[str] = (
        "Atlas of a point-set surface (METIS patches, LME charts, Shepard PU); area, Willmore "
        "energy and total Gaussian curvature vs exact values."
    )

    #: the atlas parameters (n_patches, markers_per_patch, gamma_lme, ...): AtlasSettings,
    #: with their declared constraints (AtlasSettings.parameter_constraints)
    Config = AtlasSettings

    def settings(self, ctx=None) -> AtlasSettings:
        """The run's ``atlas.*`` settings (the old ``study.*`` spellings still honoured, with a
        deprecation message); geometry defaults to 150 markers per patch."""
        from pointatlas_atlas.plugin import study_atlas_settings
        from pointatlas_atlas.settings import GEOMETRY_MARKERS_PER_PATCH

        return study_atlas_settings(ctx, self, markers_per_patch=GEOMETRY_MARKERS_PER_PATCH)

    def check_config(self) -> None:
        self.settings().check()

    def build_atlas(self, ctx, cloud):
        from pointatlas_atlas.atlas import Atlas
        from pointatlas_atlas.quadrature import check_order

        from pointatlas.errors import InputError

        if cloud.ambient_dim != 3 or (cloud.intrinsic_dim not in (None, 2)):
            raise InputError(
                f"surface_geometry needs a surface (d = 2) in R^3; {cloud.name} has D = "
                f"{cloud.ambient_dim}, d = {cloud.intrinsic_dim}. Pick a surface source "
                "(sphere, torus, connected_pipes) or a file of 3-D points on a surface.")
        s = self.settings(ctx)
        check_order(s.quadrature_order)
        from pointatlas_kit.surface_model import atlas_factories

        atlas = Atlas(s, **atlas_factories(ctx, s, hessians=s.chart_hessians,
                                           reproduction=s.chart_reproduction))
        with ctx.timed("partition"):
            atlas.partition(cloud.points, cloud.markers)
        ctx.log.info("%d markers -> %d METIS patches -> %d after recursive refinement",
                     atlas.markers_.shape[0], atlas.initial_n_patches_, atlas.labels_.max() + 1)
        warning = atlas.refinement_warning()
        if warning:
            ctx.log.warning(warning)
        with ctx.timed("charts"):
            atlas.build_charts(lambda it, **kw: ctx.progress(it, **kw))
        with ctx.timed("quadrature"):
            atlas.build_quadrature(lambda it, **kw: ctx.progress(it, **kw))
        if atlas.departed_splits_:
            ctx.log.info("%d charts departed from their points and were split (%d charts)",
                         atlas.departed_splits_, len(atlas.charts_))
        return atlas

    def run(self, ctx):
        """Load and check the cloud (cloud_checks.py: a creased or non-manifold cloud is
        refused; with atlas.allow_creases a creased one runs, its results flagged), then one
        atlas per connected component (:meth:`run_cloud`); several components are reported
        along dim ``component`` (component_results.py)."""
        from .component_results import checked_components, combine_components

        with ctx.timed("source"):
            cloud = ctx.plugin("source").load(ctx.rng("source"))
        with ctx.timed("cloud_checks"):
            s = self.settings(ctx)
            parts, comp, kept = checked_components(cloud, s.graph_neighbors, ctx.log,
                                                   allow_creases=s.allow_creases)
        if len(parts) == 1:
            ds = self.run_cloud(ctx, parts[0])
        else:
            ds = combine_components([self.run_cloud(ctx, part) for part in parts], comp, cloud)
        if kept:  # atlas.allow_creases: the integrals are flagged, never presented as clean
            ds.attrs["warnings"] = "; ".join(w for w in (kept, ds.attrs.get("warnings")) if w)
        ds["n_isolated_points"] = ((), 0 if comp is None else comp.n_isolated, {
            "long_name": "isolated points dropped (k-NN groups too small for a chart)",
            "units": "1"})
        return ds

    def _refuse_irregular_curvature(self, ctx, cloud) -> None:
        """Second derivatives of plain LME charts are not consistent on irregular nodes (README
        "Known limits": Willmore 64 % off on a random sphere): refuse curvature integrals
        there unless the charts are made for it (quartic fit, or consistent Hessians)."""
        from pointatlas_atlas.cloud_checks import IRREGULAR_SPACING, spacing_variation

        from pointatlas.errors import InputError

        s = self.settings(ctx)
        if s.chart_reproduction != "linear" or s.chart_hessians != "exact":
            return
        variation = spacing_variation(cloud.points)
        if variation > IRREGULAR_SPACING:
            raise InputError(
                f"{cloud.name}: the points are irregularly spaced (nearest-neighbour distances "
                f"vary by {100 * variation:.0f} %, above {100 * IRREGULAR_SPACING:.0f} %): "
                "the curvatures of plain LME charts are not reliable there (README, Known "
                "limits). Use the polynomial-fit charts: atlas.chart_reproduction=quartic "
                "(experiment=sphere_willmore_random adds atlas.least_squares_fit=false "
                "atlas.chart_margin=5 atlas.gamma_pu=2), or a quasi-uniform subset "
                "(source.n_points=<fewer>).")

    def run_cloud(self, ctx, cloud):
        """Atlas, integrals and per-patch results of one connected smooth cloud."""
        import xarray as xr

        self._refuse_irregular_curvature(ctx, cloud)
        atlas = self.build_atlas(ctx, cloud)
        with ctx.timed("integration"):
            qp = atlas.quadrature_points()
            g = qp.geometry
            integrands = {"area": np.ones(len(qp.weights)),
                          "willmore_energy": g["mean_curvature_squared"],
                          "total_gaussian_curvature": g["gaussian_curvature"]}
            L = len(atlas.charts_)
            per_patch = {k: np.bincount(qp.chart, weights=v * qp.weights, minlength=L)
                         for k, v in integrands.items()}
        one = {"long_name": "", "units": "1"}
        data = {}
        for key, (name, long_name) in QUANTITIES.items():
            value = float(per_patch[key].sum())
            data[name] = ((), value, {"long_name": long_name, "units": _units(key)})
            exact = cloud.exact.get(key)
            if exact is not None:
                data[name][2]["reference"] = float(exact)
                data[name][2]["reference_source"] = f"exact value of the {cloud.name} source"
                scale = abs(exact) if exact != 0 else 4.0 * np.pi
                data[f"relative_error_{name}"] = ((), abs(value - exact) / scale, {
                    "long_name": f"|computed − exact| / {'|exact|' if exact != 0 else '4π'} "
                                 f"of the {long_name.split(' ∫')[0]}", "units": "1"})
            data[f"patch_{name}"] = (("patch",), per_patch[key], {
                "long_name": f"chart contribution ∫ψ_κ(·) of the {long_name.split(' ∫')[0]}",
                "units": _units(key)})
        sizes = np.bincount(atlas.labels_, minlength=L)
        # chart test, chart_fidelity, and ψ_κ off the chart's rim (chart_coverage)
        trusted = atlas.accepted_ & atlas.charts_faithful() & atlas.charts_covered()
        data.update({
            "n_points": ((), cloud.n_points, {**one, "long_name": "number of points"}),
            "n_markers": ((), atlas.markers_.shape[0], {**one, "long_name": "number of markers"}),
            "n_patches": ((), L, {**one, "long_name": "number of patches (charts)"}),
            "n_quadrature_points": ((), len(qp.weights),
                                    {**one, "long_name": "quadrature points used, all charts"}),
            "redundancy": ((), atlas.redundancy(), {**one, "long_name": (
                "quadrature redundancy: points used / 2N triangles × rule size (Paper 2 Fig. 1)")}),
            "max_fit_residual": ((), max(c.fit_residual for c in atlas.charts_), {
                "long_name": "largest |φ_κ(ξ_a) − P_a| at the control points",
                "units": "length"}),
            "max_lost_pu": ((), max(q.lost_pu for q in atlas.quadrature_), {**one, "long_name": (
                "largest ψ_κ near a Gauss point dropped outside the LME hull (should be ~0)")}),
            "n_unaccepted_patches": ((), int((~trusted).sum()), {**one, "long_name": (
                "patches whose chart still fails the fold/stress/distortion test after repair, "
                "departs from its points or carries partition-of-unity weight on its rim (only "
                "with allow_failed_patches; else the run is refused)")}),
            "unaccepted_weight_fraction": ((), float(per_patch["area"][~trusted].sum()
                                                     / per_patch["area"].sum()),
                                           {**one, "long_name": (
                "fraction of the quadrature weight (area) on patches that fail the chart test, "
                "depart from their points or carry weight on their rim")}),
            "patch_embedder": (("patch",), *_embedder_codes(atlas)),
            "patch_split_depth": (("patch",), atlas.patch_depth_, {**one, "long_name": (
                "times the patch was bisected after the initial METIS partition (repair of "
                "the chart test or of a chart departing from its points)")}),
            "patch_markers": (("patch",), sizes, {**one, "long_name": "markers in the patch"}),
            "patch_accepted": (("patch",), trusted.astype(np.int8), {**one, "long_name": (
                "1 if the patch's chart passed the fold/stress/distortion test and stays on "
                "its points")}),
            "patch_rim_pu": (("patch",), atlas.edge_pu_, {**one, "long_name": (
                "largest ψ_κ at a rim (hull) vertex of the chart's parameters inside another "
                "chart (above 0.01 the chart's rim carries weight)")}),
            "patch_departed_weight": (("patch",), np.array(
                [(q.departure or {}).get("departed_weight", 0.0) for q in atlas.quadrature_]),
                {**one, "long_name": ("fraction of the chart's quadrature weight where it "
                                      "departs from the triangles of its samples")}),
            "patch_control_points": (("patch",), np.array([len(c.node_index) for c in
                                                          atlas.charts_]),
                                     {**one, "long_name": "control points of the chart"}),
            "patch_quadrature_points": (("patch",), np.array([len(q.weights) for q in
                                                             atlas.quadrature_]),
                                        {**one, "long_name": "quadrature points kept"}),
        })
        ds = xr.Dataset(data, coords={"patch": ("patch", np.arange(L),
                                                {"long_name": "patch index", "units": "1"})},
                        attrs={"title": f"atlas geometry of {cloud.name} ({cloud.n_points} points,"
                                        f" {ctx.plugin_name('embedder')} charts)",
                               "mean_curvature_convention": "H = κ1 + κ2"})
        warning = "; ".join(w for w in (atlas.refinement_warning(),  # allow_failed_patches
                                        gauss_bonnet_warning(atlas, float(ds[
                                            "total_gaussian_curvature"]))) if w)
        if warning:
            ds.attrs["warnings"] = warning
        for key in ("area", "willmore_energy", "total_gaussian_curvature"):
            if f"relative_error_{key}" in ds:
                ctx.log.info("%s = %.10g (exact %.10g, rel. error %.3e)", key, float(ds[key]),
                             ds[key].attrs["reference"], float(ds[f"relative_error_{key}"]))
        return ds

    @staticmethod
    def report_figures(ds):
        """Patch sizes and the per-patch share of each integral."""
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(9, 3.5))
        p = ds["patch"].values
        axes[0].bar(p, ds["patch_control_points"].values, label="control points", color="C0")
        axes[0].bar(p, ds["patch_markers"].values, label="markers", color="C1")
        axes[0].set_xlabel("patch")
        axes[0].set_ylabel("count")
        axes[0].legend()
        for name, c in (("area", "C0"), ("willmore_energy", "C2")):
            v = ds[f"patch_{name}"].values
            axes[1].plot(p, v / v.sum(), "o", ms=3, color=c, label=name)
        axes[1].set_xlabel("patch")
        axes[1].set_ylabel("share of the integral")
        axes[1].legend()
        fig.suptitle(ds.attrs.get("title", "surface geometry"))
        fig.tight_layout()
        return [("Patches", fig)]


def _embedder_codes(atlas) -> tuple[np.ndarray, dict]:
    """Per patch, the embedder whose chart was used, as CF flag codes (flag_values /
    flag_meanings in the order the repair tries them, chart_repair.repair_embedders)."""
    names = list(atlas.repair_embedders_)
    names += sorted(set(atlas.patch_embedder_) - set(names))   # 'none': never embedded
    codes = np.array([names.index(n) for n in atlas.patch_embedder_], dtype=np.int8)
    return codes, {"long_name": "embedder of the patch's chart (the first that passed the "
                                "chart test; the least bad if none did)", "units": "1",
                   "flag_values": np.arange(len(names), dtype=np.int8),
                   "flag_meanings": " ".join(names)}


def _units(key: str) -> str:
    return {"area": "length^2", "willmore_energy": "1", "total_gaussian_curvature": "1"}[key]


#: |∫K/2π − χ| above which a closed surface's curvatures are flagged (χ the nearest even
#: integer): 0.1 is ∫K off by 0.2π, 5 % of a sphere's 4π (converged clouds: below 1e-3)
MAX_EULER_DEFECT = 0.1


def gauss_bonnet_warning(atlas, total_k: float) -> str | None:
    """The atlas's own check of its curvatures on a closed surface (oriented 'outward':
    it encloses a volume): Gauss–Bonnet, ∫K dA = 2π χ with χ = 2 − 2g an even integer ≤ 2.
    A total curvature far from every such value (e.g. ∫K/2π = 0.10 on a pyvista ellipsoid
    with poles crowded by its parametrisation) means the charts' second derivatives are
    wrong somewhere: the warning marks the results as not trustworthy."""
    if "outward" not in str(getattr(atlas, "orientation_", "")):
        return None
    chi = total_k / (2 * np.pi)
    nearest = min(2.0, 2.0 * np.round(chi / 2.0))
    if abs(chi - nearest) <= MAX_EULER_DEFECT:
        return None
    return (f"Gauss–Bonnet fails on this closed surface: ∫K dA / 2π = {chi:.3g}, not an even "
            f"integer ≤ 2 (nearest {nearest:g}): the curvatures (Willmore energy, ∫K, H, K) are "
            "not trustworthy. Try a denser or more even sample, or other chart settings "
            "(atlas.chart_reproduction, atlas.markers_per_patch).")
