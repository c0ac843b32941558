"""A cloud of several connected components: check it, split it, and join the results.

A study that needs one smooth surface per atlas (surface_geometry) checks its cloud with
:func:`pointatlas_atlas.cloud_checks.check_cloud` (components of the k-NN graph at the chart
scale, isolated points, creases, non-disc neighbourhoods), refuses it with one line if it is
not made of smooth surfaces, and otherwise runs one atlas per component; the per-component
datasets are joined here along a new dim ``component``.
"""
from __future__ import annotations

import numpy as np

from pointatlas.errors import InputError
from pointatlas.pointcloud import PointCloud

#: per-component copies (dim ``component``) of these scalar results
PER_COMPONENT = ("area", "willmore_energy", "total_gaussian_curvature", "n_points",
                 "n_patches", "n_unaccepted_patches")


def checked_components(cloud: PointCloud, n_neighbors: int, log=None,
                       allow_creases: bool = False):
    """(parts, components, kept): the connected components of a surface cloud in R³ as
    clouds, largest first, the :class:`~pointatlas_atlas.cloud_checks.Components` (None if
    the cloud is not a surface in R³: then ``[cloud]``, unchecked), and the warning the
    results must carry if ``allow_creases`` kept a creased cloud (else None).

    Raises InputError (one line, with where and the fix) for creases (unless
    ``allow_creases``), non-disc neighbourhoods or a cloud too unevenly sampled. Isolated
    points are dropped (counted in ``Components.n_isolated``, logged); markers follow the
    component of their nearest point.
    """
    from pointatlas_atlas.cloud_checks import check_cloud, components_message, verdict
    from scipy.spatial import cKDTree

    if cloud.ambient_dim != 3 or cloud.intrinsic_dim not in (None, 2):
        return [cloud], None, None
    check = check_cloud(cloud.points, n_neighbors)
    reason, kept = verdict(cloud.points, check, cloud.name, allow_creases)
    if reason:
        raise InputError(reason)
    if log is not None and kept:
        log.warning("%s", kept)
    comp = check.components
    if log is not None and comp.n_isolated:
        log.warning("%s: %d isolated points dropped (groups of fewer than the minimum, far "
                    "from the rest)", cloud.name, comp.n_isolated)
    if log is not None and len(comp.sizes) > 1:
        log.info("%s: %s; one atlas each", cloud.name, components_message(comp))
    if len(comp.sizes) == 1 and not comp.n_isolated:
        return [cloud], comp, kept
    marker_label = None
    if cloud.markers is not None:
        marker_label = comp.labels[cKDTree(cloud.points).query(cloud.markers)[1]]
    exact = cloud.exact if len(comp.sizes) == 1 else {}
    parts = []
    for c in range(len(comp.sizes)):
        keep = comp.labels == c
        parts.append(PointCloud(
            points=cloud.points[keep], intrinsic_dim=cloud.intrinsic_dim, exact=dict(exact),
            markers=None if marker_label is None else cloud.markers[marker_label == c],
            parameters=None if cloud.parameters is None else cloud.parameters[keep],
            name=cloud.name if len(comp.sizes) == 1 else f"{cloud.name} component {c}",
            info=dict(cloud.info)))
    return parts, comp, kept


def combine_components(datasets, comp, cloud: PointCloud):
    """One dataset from one per component: totals under the usual names, per-component
    values along dim ``component``, patches numbered on, with ``patch_component``.

    Totals: sums for the integrals and counts (``n_*``), maxima for ``max_*``, the redundancy
    Σ used / Σ (used / redundancy); other scalars only if equal on every component. The
    relative errors are recomputed from the totals against the cloud's exact values.
    """
    import xarray as xr

    n = len(datasets)
    first = datasets[0]
    data = {}
    for name, var in first.data_vars.items():
        values = [ds[name].values for ds in datasets if name in ds]
        attrs = dict(var.attrs)
        if len(values) != n:
            continue
        if var.dims == ():
            v = np.array(values)
            if name.startswith("relative_error_"):
                continue
            if name.startswith("n_") or name in ("area", "willmore_energy",
                                                 "total_gaussian_curvature"):
                total = v.sum()
            elif name.startswith("max_"):
                total = v.max()
            elif name == "redundancy" and "n_quadrature_points" in first:
                used = np.array([float(ds["n_quadrature_points"]) for ds in datasets])
                total = used.sum() / np.sum(used / v)
            elif np.all(v == v[0]):
                total = v[0]
            else:
                total = None
            if total is not None:
                data[name] = ((), total, attrs)
            if name in PER_COMPONENT or total is None:
                data[f"component_{name}"] = (("component",), v, {
                    **attrs, "long_name": f"{attrs.get('long_name', name)}, per component"})
        elif var.dims[0] == "patch":
            data[name] = (var.dims, np.concatenate(values, axis=0), attrs)
        elif all(np.shape(v) == np.shape(values[0]) for v in values):
            data[f"component_{name}"] = (("component", *var.dims), np.stack(values), attrs)
    sizes = [ds.sizes.get("patch", 0) for ds in datasets]
    data["patch_component"] = (("patch",), np.repeat(np.arange(n), sizes),
                               {"long_name": "connected component of the patch", "units": "1"})
    for key in ("area", "willmore_energy", "total_gaussian_curvature"):
        exact = cloud.exact.get(key)
        if exact is not None and key in data:
            data[key][2].update(reference=float(exact),
                                reference_source=f"exact value of the {cloud.name} source")
            scale = abs(exact) if exact != 0 else 4.0 * np.pi
            data[f"relative_error_{key}"] = ((), abs(float(data[key][1]) - exact) / scale, {
                "long_name": f"|computed − exact| / scale of the {key}, all components",
                "units": "1"})
    coords = {"component": ("component", np.arange(n),
                            {"long_name": "connected component (largest first)",
                             "units": "1"})}
    if "patch" in first.coords:
        coords["patch"] = ("patch", np.arange(sum(sizes)), dict(first["patch"].attrs))
    attrs = dict(first.attrs)
    attrs["title"] = (f"atlas geometry of {cloud.name} ({n} components, "
                      f"{int(np.sum(comp.sizes))} points)")
    attrs["component_centroids"] = np.asarray(comp.centroids, dtype=np.float64).ravel()
    warnings = [f"component {i}: {ds.attrs['warnings']}" for i, ds in enumerate(datasets)
                if ds.attrs.get("warnings")]
    if warnings:
        attrs["warnings"] = "; ".join(warnings)
    return xr.Dataset(data, coords=coords, attrs=attrs)
