"""A solved shell as an xarray Dataset (dims point, dim) and as a ParaView ``.vtp`` file."""
from __future__ import annotations

import os
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
        "n_quadrature_points": ((), len(model.quadrature.weights), {
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


def write_vtp(model, path: Path, magnification: float = 1.0) -> Path:
    """The sampled points with their displacement (and the deformed position, magnified) as a
    PolyData ``.vtp`` (written to a temporary name, then renamed)."""
    import pyvista as pv

    path = Path(path)
    cloud = pv.PolyData(np.ascontiguousarray(model.points))
    cloud.point_data["displacement"] = np.ascontiguousarray(model.displacement)
    cloud.point_data["displacement_magnitude"] = np.linalg.norm(model.displacement, axis=1)
    cloud.point_data["deformed"] = model.points + magnification * model.displacement
    cloud.point_data["on_boundary"] = model.boundary.astype(np.int8)
    tmp = path.with_name(path.stem + ".partial.vtp")
    cloud.save(str(tmp))
    os.replace(tmp, path)
    return path
