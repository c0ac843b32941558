"""Mirror symmetry of a phase field: ``symmetry_defect`` of the fracture study.

With ``study.mirror_plane`` [nx, ny, nz, d] (n·x = d) each sampled point x_a is matched
with the point at its mirror image x_a − 2 (n·x_a − d) n / |n|² (within MATCH_TOL of the
cloud's size: the cloud must be mirror symmetric point for point, e.g. ``six_pipes`` with
structured sampling; otherwise the run is refused rather than interpolated), and

    symmetry_defect = ‖υ − υ∘m‖₂ / ‖υ‖₂      (the issue's relative L2 difference),

at the last increment, with the same figure along ``increment``
(``symmetry_defect_history``) and relative to the damage, ‖υ − υ∘m‖₂ / ‖1 − υ‖₂
(``symmetry_defect_damage``, NaN while nothing is damaged), which is O(1) for a crack on one
side only and near 0 for a symmetric one, whatever the size of the intact region.
"""
from __future__ import annotations

import numpy as np

#: a mirror image must be this close to a sampled point, relative to the cloud's diameter
MATCH_TOL = 1e-9


def check_plane(plane, key: str) -> np.ndarray:
    """The plane [nx, ny, nz, d] as a float array, or ConfigError naming ``study.<key>``."""
    from pointatlas.errors import ConfigError

    p = np.asarray(plane, dtype=float).ravel()
    if p.shape != (4,) or not np.all(np.isfinite(p)) or not np.linalg.norm(p[:3]) > 0:
        raise ConfigError(f"study.{key} = {plane!r} must be a plane [nx, ny, nz, d] "
                          "(n·x = d, n ≠ 0), e.g. [1, 0, 0, 0].")
    return p


def plane_offset(points: np.ndarray, plane) -> tuple[np.ndarray, np.ndarray]:
    """(n·x − d for every row of ``points``, unit normal n) of the plane [nx, ny, nz, d]
    (n·x = d), normalised: the signed distance to the plane."""
    p = np.asarray(plane, dtype=float).ravel()
    norm = np.linalg.norm(p[:3])
    n = p[:3] / norm
    return np.asarray(points, dtype=float) @ n - p[3] / norm, n


def mirror_index(points: np.ndarray, plane) -> np.ndarray:
    """m (n,) with points[m[a]] the mirror image of points[a], or InputError if the cloud
    is not mirror symmetric about ``plane``."""
    from scipy.spatial import cKDTree

    from pointatlas.errors import InputError

    p = np.asarray(plane, dtype=float)
    offset, n = plane_offset(points, p)
    image = points - 2.0 * offset[:, None] * n
    distance, index = cKDTree(points).query(image)
    size = float(np.ptp(points, axis=0).max())
    if distance.max() > MATCH_TOL * size:
        worst = int(np.argmax(distance))
        raise InputError(
            f"study.mirror_plane {list(map(float, p))}: the cloud is not mirror symmetric "
            f"about it (the image of point {worst} is {distance[worst]:.3g} from the nearest "
            "point), so symmetry_defect cannot be measured at the points. Use a mirror "
            "symmetric cloud (e.g. source=six_pipes with source.sampling=structured) or "
            "remove study.mirror_plane.")
    return index


def symmetry_defect(ds, plane):
    """ds with ``symmetry_defect``, ``symmetry_defect_history``, ``symmetry_defect_damage``
    (module doc)."""
    m = mirror_index(ds["position"].values, plane)
    v = ds["phase_field"].values
    diff = np.linalg.norm(v - v[:, m], axis=1)
    history = diff / np.maximum(np.linalg.norm(v, axis=1), 1e-300)
    damage = np.linalg.norm(1.0 - v[-1])
    label = list(map(float, np.asarray(plane, dtype=float)))
    ds["symmetry_defect_history"] = (("increment",), history, {
        "units": "1", "long_name": f"‖υ − υ∘mirror‖ / ‖υ‖, mirror plane {label}"})
    ds["symmetry_defect"] = ((), float(history[-1]), {
        "units": "1", "long_name": f"‖υ − υ∘mirror‖ / ‖υ‖ at the last increment, mirror "
                                   f"plane {label}"})
    ds["symmetry_defect_damage"] = ((), float(diff[-1] / damage) if damage > 0 else np.nan, {
        "units": "1", "long_name": "‖υ − υ∘mirror‖ / ‖1 − υ‖ at the last increment"})
    return ds
