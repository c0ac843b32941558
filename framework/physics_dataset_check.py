"""Conformance of what a physics plugin's ``solve`` returns: the schema of its Dataset.

A physics declares ``conformance_case``, a class attribute holding Config values that make a
small solvable problem on an open curved patch with one boundary curve (supports on its
boundary, a load or a source)::

    conformance_case: ClassVar[dict] = {
        "c": 1.0, "source_term": "1",
        "supports": [{"where": {"box": [-1, -1, -1, 2, 2, 2]}, "value": 0.0}]}

:func:`solve_conformance_case` builds the physics with them, builds the patch itself
(:func:`pointatlas.physics_conformance.curved_points`: z = 0.3 x² − 0.2 xy + 0.25 y² over
[0, 1]², 15 × 15 jittered points, every point in the box [0, 1]² × [0, 0.35]), a
:class:`~pointatlas.context.RunContext` choosing ``embedder=pca``, ``approximant=lme`` and
``atlas=default`` (through the registry only) and calls ``solve(ctx, cloud=...,
atlas_settings=...)``. :func:`check_physics_dataset` then holds the Dataset to the results
rules of :mod:`pointatlas.results`:

* every dimension named (none of xarray's default ``dim_0``, ``dim_1``...);
* every data variable and coordinate with ``long_name`` and ``units`` attrs, non-empty strings
  (units ``'1'`` when dimensionless);
* ``point`` a coordinate (one entry per point of the cloud);
* each declared field ``f`` (``cls.fields``) a data variable named ``f.name`` (or
  ``f.name + '_field'`` where the results use ``f.name`` for a derived scalar, as the shell
  study does for its reference displacement) with the dimension ``point`` and
  ``f.components`` values per point;
* every numeric value finite.

Each broken rule raises ``AssertionError`` naming the physics, the variable and the rule.
"""
from __future__ import annotations

import re
from typing import Any, Sequence

import numpy as np

#: the atlas of the conformance patch: a few patches of 100 markers, order-4 quadrature
CONFORMANCE_ATLAS = {"markers_per_patch": 100, "quadrature_order": 4}
#: points per side of the conformance patch (15² = 225 points)
CONFORMANCE_POINTS_PER_SIDE = 15
_DEFAULT_DIM = re.compile(r"dim_\d+$")


def conformance_cloud(n: int = CONFORMANCE_POINTS_PER_SIDE, seed: int = 0):
    """The open doubly curved patch of :func:`~pointatlas.physics_conformance.curved_points`
    as a :class:`~pointatlas.pointcloud.PointCloud` (n² points, one boundary curve)."""
    from .physics_conformance import curved_points
    from .pointcloud import PointCloud

    _, P = curved_points(n, seed)
    return PointCloud(points=P, intrinsic_dim=2, name="conformance patch")


def solve_conformance_case(cls: type, case: dict, **kwargs: Any):
    """(physics, cloud, Dataset): ``cls`` built from ``case`` merged with ``kwargs`` (kwargs
    win), solved on :func:`conformance_cloud` with the atlas :data:`CONFORMANCE_ATLAS`."""
    import copy
    import logging
    import tempfile
    from pathlib import Path

    from .context import RunContext

    physics = cls(**copy.deepcopy({**case, **kwargs}))  # the class's dicts stay as declared
    cloud = conformance_cloud()
    with tempfile.TemporaryDirectory(prefix="pointatlas-conformance-") as run_dir:
        ctx = RunContext(config={"embedder": {"n_components": 2},
                                 "atlas": dict(CONFORMANCE_ATLAS)},
                         choices={"embedder": "pca", "approximant": "lme", "atlas": "default"},
                         seed=0, run_dir=Path(run_dir),
                         log=logging.getLogger("pointatlas.testing"))
        atlas_settings = ctx.plugin("atlas").settings()
        ds = physics.solve(ctx, cloud=cloud, atlas_settings=atlas_settings)
    return physics, cloud, ds


def check_physics_dataset(ds, fields: Sequence, name: str, n_points: int | None = None) -> None:
    """AssertionError naming the variable and the rule ``ds`` (what physics ``name``'s
    ``solve`` returned) breaks (see the module doc); ``fields``: its declared kit fields;
    ``n_points``: the size of the cloud it was solved on, if known."""
    import xarray as xr

    from .results import check_variables

    assert isinstance(ds, xr.Dataset), (
        f"{name}.solve returned {type(ds).__name__}; it must return an xarray.Dataset")
    where = f"{name}.solve's Dataset:"
    for var_name, var in {**ds.data_vars, **ds.coords}.items():
        default = [d for d in var.dims if _DEFAULT_DIM.match(str(d))]
        assert not default, (
            f"{where} variable {var_name!r} has unnamed dimension(s) {default} (xarray's "
            "default names): give every dimension a name, e.g. ('point', 'component')")
    try:
        check_variables(ds)
    except ValueError as exc:
        raise AssertionError(f"{where} {exc}") from None  # names the variables
    for var_name, var in {**ds.data_vars, **ds.coords}.items():
        for key in ("long_name", "units"):
            value = var.attrs[key]
            assert isinstance(value, str) and value.strip(), (
                f"{where} variable {var_name!r} has {key}={value!r}: it must be a non-empty "
                "string (units '1' if dimensionless)")
    assert "point" in ds.coords, (
        f"{where} 'point' is not a coordinate: index the fields by ds.assign_coords(point="
        "('point', np.arange(n), {'long_name': ..., 'units': '1'}))")
    if n_points is not None:
        assert ds.sizes["point"] == n_points, (
            f"{where} 'point' has {ds.sizes['point']} entries for a cloud of {n_points} points")
    for f in fields:
        _check_field(ds, f, where)
    for var_name, var in {**ds.data_vars, **ds.coords}.items():
        if var.dtype.kind in "fc":
            bad = int((~np.isfinite(var.values)).sum())
            assert not bad, (
                f"{where} variable {var_name!r} has {bad} non-finite value(s) (NaN or inf): "
                "a solved problem's results must be finite")


def _check_field(ds, f, where: str) -> None:
    """A declared field is a data variable over ``point`` with ``f.components`` values each."""
    present = [v for v in (f.name, f"{f.name}_field") if v in ds.data_vars]
    var_name = next((v for v in present if "point" in ds[v].dims), None)
    assert var_name is not None, (
        f"{where} declared field {f.name!r} is missing: " + (
            f"variable {present[0]!r} has dims {tuple(map(str, ds[present[0]].dims))}, "
            "without 'point'" if present else
            f"no data variable {f.name!r} among {sorted(map(str, ds.data_vars))}") +
        f"; give it as a data variable {f.name!r} over the dimension 'point'")
    var = ds[var_name]
    per_point = var.size // max(ds.sizes["point"], 1)
    assert per_point == f.components, (
        f"{where} field variable {var_name!r} holds {per_point} value(s) per point; the "
        f"declared field {f.name!r} has {f.components} component(s)")
