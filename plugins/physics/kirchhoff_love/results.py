"""A solved shell as an xarray Dataset (dims point, dim) and as a ParaView ``.vtp`` file."""
from __future__ import annotations

from pathlib import Path

import numpy as np

LENGTH = "length"


def field_dataset(model):
    """Displacement field, sizes, energy and the time split of a solved :class:`ShellModel`."""
    import xarray as xr

    U = model.nodal_displacement
    energy = 0.5 * float(model.forces.ravel() @ U.ravel())
    one = {"units": "1"}
    times = {f"time_{k}": ((), float(v), {"long_name": f"wall time of stage '{k}'",
                                          "units": "s"}) for k, v in model.times.items()}
    data = {
        "position": (("point", "dim"), model.points, {"long_name": "sampled point x_a",
                                                      "units": LENGTH}),
        "displacement_field": (("point", "dim"), model.displacement, {
            "long_name": "displacement u(x_a) = Σ_b p_b(ξ_a) U_b at the sampled points",
            "units": LENGTH}),
        "on_boundary": (("point",), model.boundary.astype(np.int8), {
            **one, "long_name": "1 if the point was detected on the boundary"}),
        "dof": ((), model.dof, {**one, "long_name": "degrees of freedom (3 × control points, "
                                                    "ghost nodes included)"}),
        "n_points": ((), model.points.shape[0], {**one, "long_name": "sampled points"}),
        "n_ghosts": ((), model.n_ghosts, {**one, "long_name": "ghost nodes beyond the boundary"}),
        "n_patches": ((), len(model.atlas.charts_), {**one, "long_name": "patches (charts)"}),
        "n_quadrature_points": ((), sum(len(c.weights) for c in model.atlas.quadrature_), {
            **one, "long_name": "quadrature points over all charts"}),
        "n_constraints": ((), model.constraints.matrix.shape[0], {
            **one, "long_name": "constraint rows of the supports"}),
        "strain_energy": ((), energy, {"long_name": "strain energy ½ FᵀU (linear analysis)",
                                       "units": "energy"}),
        "max_displacement": ((), float(np.linalg.norm(model.displacement, axis=1).max()), {
            "long_name": "largest |u| at the sampled points", "units": LENGTH}),
        "constraint_violation": ((), float(model.solve_info.violation), {
            "long_name": "max |CU − g| after the augmented-Lagrangian loop", "units": LENGTH}),
        "al_iterations": ((), model.solve_info.iterations, {
            **one, "long_name": "augmented-Lagrangian iterations"}),
        **times,
    }
    return xr.Dataset(data, coords={
        "point": ("point", np.arange(model.points.shape[0]), {"long_name": "point index",
                                                               "units": "1"}),
        "dim": ("dim", ["x", "y", "z"], {"long_name": "Cartesian component", "units": "1"})})


def write_vtp(model, path: Path, magnification: float = 1.0, units_system: str = "SI") -> Path:
    """The solved shell as a ParaView ``.vtp`` (:mod:`pointatlas_kit.paraview`, written
    atomically): the sampled points x_a (reference configuration) with the triangles of the
    surface from the atlas's charts (:mod:`pointatlas_kit.surface_mesh`), point arrays ``u``
    (displacement, length), ``u_magnitude`` |u| (length), ``deformed`` x_a + magnification·u
    (length) and ``on_boundary`` (1), each with its ``NAME_units`` (in ``units_system``, as
    the run's results.nc) and ``NAME_quantity`` in the field data, and the field value
    ``magnification`` (1): Warp By Vector with ``u`` at this scale factor draws the deformed
    shape that ``deformed`` holds."""
    from pointatlas_kit.paraview import Array, write_vtp as write
    from pointatlas_kit.surface_mesh import surface_triangles

    m = float(magnification)
    if not np.isfinite(m):
        from pointatlas.errors import InputError

        raise InputError(f"magnification = {magnification!r}: give a finite number.")
    u = np.asarray(model.displacement, dtype=np.float64)
    x = np.asarray(model.points, dtype=np.float64)
    triangles = surface_triangles(model.atlas, x.shape[0])
    return write(path, x, triangles, {
        "u": Array(u, LENGTH, "displacement u(x_a) at the sampled points"),
        "u_magnitude": Array(np.linalg.norm(u, axis=1), LENGTH, "|u|"),
        "deformed": Array(x + m * u, LENGTH, f"deformed position x_a + {m:g}·u"),
        "on_boundary": Array(model.boundary.astype(np.int8), "1",
                             "1 if the point was detected on the boundary")},
        {"magnification": Array(m, "1", "scale factor of u in 'deformed' (Warp By Vector)")},
        units_system)
