"""ParaView files of a sampled surface: a ``.vtp`` with triangles and arrays that carry their
units, and a ``.pvd`` collection of such files along a path, which ParaView animates.

What ParaView sees in a ``.vtp`` written by :func:`write_vtp`:

- Points: the sampled points x_a in the reference (undeformed) configuration (length).
- Cells: the triangles (Polys) of the sampled surface (:mod:`.surface_mesh`), so the
  Surface representation shows the shell; a point that no triangle uses (normally none) gets
  a vertex cell (Verts), so every point is drawn.
- Point data: the arrays given, e.g. ``u`` (displacement vector, length) and
  ``u_magnitude``: colour by them; Filters → Warp By Vector with Vectors ``u`` and Scale
  Factor = the field value ``magnification`` shows the deformed shape.
- Field data: for every point array ``NAME`` the one-string arrays ``NAME_units``, the
  UDUNITS string of the run's ``units_system`` as in ``results.nc`` (``m``, ``J m-2``; ``1``
  for a dimensionless array), ``NAME_quantity``, the abstract quantity it came from
  (``length``, ``energy/length²``; the results' ``quantity`` attr), and ``NAME_long_name``
  (what it is); single values (e.g. ``magnification``, ``load_factor``) with the same three;
  ``units_system``; in a step of a series, ``TimeValue`` (the step's time, which ParaView's
  readers use). ParaView lists them in the Information panel (Data Arrays, field-data icon)
  and shows their values in a Spreadsheet view with Attribute = Field Data; in Python,
  ``mesh.field_data["u_units"][0]``.

A ``.pvd`` (:func:`write_pvd`, ``<VTKFile type="Collection">``) has one ``<DataSet
timestep=… file=…>`` per step, file paths relative to the ``.pvd``, timesteps strictly
increasing; :class:`SnapshotSeries` names the step files ``snapshots/increment_NNNN.vtp``.

Every file is written under a temporary name ``.<name>.<random>.tmp`` beside it, flushed to
disk and renamed over the final name: a reader never sees half a file, and a kill leaves at
worst a ``.tmp`` leftover (:func:`pointatlas.run_files.remove_partial_files`).
"""
from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Optional, Sequence
from xml.sax.saxutils import quoteattr

import numpy as np

from pointatlas.errors import InputError


@dataclass(frozen=True)
class Array:
    """Values, their units — an abstract quantity such as ``'length'`` or
    ``'energy/length²'`` (:mod:`pointatlas.units`; ``'1'``: dimensionless) or a UDUNITS
    string — and a description."""

    values: object
    units: str
    long_name: str


def units_system_of(ctx) -> str:
    """The run's ``units_system`` (SI unless set), as the results are written in."""
    config = getattr(ctx, "config", None)
    return str((config.get("units_system") if config is not None else None) or "SI")


def surface_polydata(points, triangles, point_data: Mapping[str, Array],
                     field_data: Optional[Mapping[str, Array]] = None,
                     units_system: str = "SI"):
    """A ``pyvista.PolyData``: ``points`` (n, 3), the ``triangles`` (T, 3) indices as polys,
    a vertex cell for each point in no triangle, ``point_data`` arrays (n, …) and
    ``field_data`` values, each with ``NAME_units`` (in ``units_system``), ``NAME_quantity``
    and ``NAME_long_name`` (module doc)."""
    import pyvista as pv

    from pointatlas.units import UNIT_SYSTEMS, parse_quantity, to_udunits

    if units_system not in UNIT_SYSTEMS:
        raise InputError(f"units_system = {units_system!r} is unknown; use one of "
                         f"{', '.join(UNIT_SYSTEMS)}.")
    X = np.ascontiguousarray(points, dtype=np.float64)
    if X.ndim != 2 or X.shape[1] != 3 or not len(X):
        raise InputError(f"a .vtp needs points of shape (n, 3), n ≥ 1; got {X.shape}.")
    T = np.asarray(triangles)
    if T.size == 0:
        T = np.zeros((0, 3), np.int64)
    if T.ndim != 2 or T.shape[1] != 3 or T.dtype.kind not in "iu" or \
            (len(T) and (T.min() < 0 or T.max() >= len(X))):
        raise InputError(f"a .vtp's triangles must be (T, 3) integer indices into its {len(X)} "
                         f"points; got shape {T.shape}, dtype {T.dtype}.")
    used = np.zeros(len(X), bool)
    used[T.ravel()] = True
    lonely = np.flatnonzero(~used)
    mesh = pv.PolyData(X, faces=np.column_stack([np.full(len(T), 3), T]).ravel(),
                       verts=np.column_stack([np.ones(len(lonely), np.int64), lonely]).ravel()
                       if len(lonely) else None)
    for name, a in point_data.items():
        v = np.asarray(a.values)
        if v.shape[:1] != (len(X),) or v.ndim > 2:
            raise InputError(f"point array {name!r} has shape {v.shape}; a .vtp of {len(X)} "
                             f"points needs ({len(X)},) or ({len(X)}, k).")
        mesh.point_data[name] = np.ascontiguousarray(v)
    for name, a in (field_data or {}).items():
        mesh.field_data[name] = np.atleast_1d(np.asarray(a.values))
    for name, a in {**point_data, **(field_data or {})}.items():
        _add_string(mesh, f"{name}_units", to_udunits(str(a.units), units_system))
        if parse_quantity(str(a.units)) is not None:
            _add_string(mesh, f"{name}_quantity", a.units)
        _add_string(mesh, f"{name}_long_name", a.long_name)
    _add_string(mesh, "units_system", units_system)
    return mesh


def _add_string(mesh, name: str, text) -> None:
    """A one-value string array in the field data, UTF-8 (unit labels such as
    ``energy/length²`` kept as the Dataset writes them)."""
    from vtkmodules.vtkCommonCore import vtkStringArray

    a = vtkStringArray()
    a.SetName(name)
    a.InsertNextValue(str(text))
    mesh.GetFieldData().AddArray(a)


def write_vtp(path, points, triangles, point_data: Mapping[str, Array],
              field_data: Optional[Mapping[str, Array]] = None,
              units_system: str = "SI") -> Path:
    """Write :func:`surface_polydata` to ``path`` (binary, zlib) atomically; returns ``path``."""
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter

    path = Path(path)
    if path.suffix != ".vtp":
        raise InputError(f"{path}: a PolyData file must end in .vtp.")
    mesh = surface_polydata(points, triangles, point_data, field_data, units_system)
    writer = vtkXMLPolyDataWriter()
    writer.SetInputData(mesh)
    writer.SetDataModeToBinary()
    writer.SetCompressorTypeToZLib()

    def write(tmp):
        writer.SetFileName(tmp)
        if writer.Write() != 1:
            raise OSError(f"VTK could not write {path}")
    return _atomic(path, write)


def write_pvd(path, steps: Sequence[tuple[float, object]]) -> Path:
    """A ``.pvd`` collection at ``path`` listing ``steps`` (timestep, step file) in order:
    the files must exist, the timesteps increase strictly; file paths are written relative
    to the ``.pvd``'s folder. Written atomically; returns ``path``."""
    path = Path(path)
    if path.suffix != ".pvd":
        raise InputError(f"{path}: a ParaView collection file must end in .pvd.")
    times = np.array([float(t) for t, _ in steps], dtype=np.float64)
    if not np.all(np.isfinite(times)) or np.any(np.diff(times) <= 0):
        raise InputError(f"{path.name}: the timesteps must be finite and increase strictly; "
                         f"got {times.tolist()}.")
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
             "  <Collection>"]
    for t, f in zip(times, (Path(f) for _, f in steps)):
        if not f.is_file():
            raise InputError(f"{path.name} would list {f}, which does not exist.")
        rel = Path(os.path.relpath(f.resolve(), path.parent.resolve())).as_posix()
        lines.append(f'    <DataSet timestep="{float(t)!r}" group="" part="0" '
                     f"file={quoteattr(rel)}/>")
    lines += ["  </Collection>", "</VTKFile>", ""]
    text = "\n".join(lines)

    def write(tmp):
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)
    return _atomic(path, write)


class SnapshotSeries:
    """Step files ``<folder>/increment_NNNN.vtp`` (NNNN = increment index, from 0) of a path
    and the ``.pvd`` at ``pvd`` listing them (paths relative to the ``.pvd``)."""

    def __init__(self, pvd, folder):
        self.pvd, self.folder = Path(pvd), Path(folder)

    def path(self, k: int) -> Path:
        """The step file of increment ``k`` (its folder is made)."""
        self.folder.mkdir(parents=True, exist_ok=True)
        return self.folder / f"increment_{int(k):04d}.vtp"

    def publish(self, timesteps: Sequence[float]) -> Path:
        """Rewrite the ``.pvd`` listing increments 0 … len(timesteps) − 1 (their files must be
        written already) with these timesteps."""
        return write_pvd(self.pvd, [(t, self.path(k)) for k, t in enumerate(timesteps)])


def _atomic(path: Path, write) -> Path:
    """``write(tmp)`` to a temporary file beside ``path``, fsync, rename over ``path``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        write(tmp)
        with open(tmp, "rb") as fh:
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
