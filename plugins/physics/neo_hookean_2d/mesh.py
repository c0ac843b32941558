"""The reference body: a mesh of linear triangles in the plane and the clamped nodes.

A :class:`TriangleMesh` holds the reference positions X (n, 2), in length units, and the
triangles (m, 3) as node indices, counter-clockwise. It is built by

* :func:`tapered_column`: a stand-in for the body of Millán (2012) Fig. 19 (whose exact outline
  the thesis only shows as a picture): a column of height H clamped at y = 0, its width
  tapering linearly from ``base_width`` at the bottom to ``top_width`` at the top
  (``top_width = base_width`` is a rectangle). The thesis sketch gives 1.50, 0.24 and 0.08
  and its mesh has 9 428 triangles, 4 934 nodes and 434 boundary nodes, which a column of
  height 1.5 and mean width 0.16 reproduces (perimeter² / area ≈ 46). The triangulation is
  structured and mirror-symmetric about x = 0 (the diagonals of the left half of the columns
  of cells lean one way, those of the right half the other), like the thesis' symmetric
  problem;
* :func:`read_mesh`: a user's 2-D mesh file (gmsh ``.msh``, VTK ``.vtu``/``.vtk`` and any
  format meshio reads), keeping its linear triangles.

:func:`clamped_nodes` turns a clamp selector of the Config into a mask of nodes.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: clamp selectors: a name, or a mapping with one of these keys
CLAMP_KEYS = ("y_below", "box")


@dataclass(frozen=True)
class TriangleMesh:
    """Reference positions ``nodes`` (n, 2) in length units and ``triangles`` (m, 3) node
    indices, counter-clockwise (positive reference area)."""

    nodes: np.ndarray
    triangles: np.ndarray

    @property
    def n_nodes(self) -> int:
        return len(self.nodes)

    @property
    def n_triangles(self) -> int:
        return len(self.triangles)

    @property
    def areas(self) -> np.ndarray:
        """Signed reference area of each triangle (length², > 0 when counter-clockwise)."""
        p = self.nodes[self.triangles]
        e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        return 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])

    def to_skfem(self):
        """The same mesh as scikit-fem's ``MeshTri`` (scikit-fem is an optional dependency)."""
        from skfem import MeshTri

        return MeshTri(np.ascontiguousarray(self.nodes.T),
                       np.ascontiguousarray(self.triangles.T))


def tapered_column(height: float = 1.5, base_width: float = 0.24, top_width: float = 0.08,
                   n_triangles: int = 9428) -> TriangleMesh:
    """Column x ∈ [−w(y)/2, w(y)/2], y ∈ [0, H], w(y) = w_b + (w_t − w_b) y / H, cut into
    nx × ny cells of two triangles each, nx even, with 2 nx ny as close to ``n_triangles`` as
    cells of aspect ≈ 1 allow (nx ≈ √(n_triangles/2 · w̄/H), w̄ the mean width).
    ``n_triangles=9428`` gives nx = 22, ny = 214: 9 416 triangles, 4 945 nodes."""
    mean_width = 0.5 * (base_width + top_width)
    nx = max(2, 2 * int(round(0.5 * np.sqrt(0.5 * n_triangles * mean_width / height))))
    ny = max(1, int(round(n_triangles / (2 * nx))))
    s = np.linspace(-0.5, 0.5, nx + 1)
    eta = np.linspace(0.0, 1.0, ny + 1)
    width = base_width + (top_width - base_width) * eta
    x = s[None, :] * width[:, None]
    y = np.broadcast_to(height * eta[:, None], x.shape)
    nodes = np.column_stack([x.ravel(), y.ravel()])
    i, j = np.meshgrid(np.arange(nx), np.arange(ny))
    i, j = i.ravel(), j.ravel()
    n00 = j * (nx + 1) + i
    n10, n01 = n00 + 1, n00 + nx + 1
    n11 = n01 + 1
    left = i < nx // 2                       # diagonal n00–n11 on the left, n10–n01 on the right
    t1 = np.where(left[:, None], np.column_stack([n00, n10, n11]), np.column_stack([n00, n10, n01]))
    t2 = np.where(left[:, None], np.column_stack([n00, n11, n01]), np.column_stack([n10, n11, n01]))
    return TriangleMesh(nodes, np.vstack([t1, t2]).astype(np.int64))


def _read_cells(path: Path):
    """(points, {cell type: connectivity}) of a mesh file: meshio, else pyvista for VTK."""
    try:
        import meshio
    except ImportError:
        meshio = None
    if meshio is not None:
        import contextlib
        import io

        sink = io.StringIO()                  # meshio prints before it exits
        with contextlib.redirect_stderr(sink), contextlib.redirect_stdout(sink):
            m = meshio.read(path)
        return np.asarray(m.points, float), {c.type: np.asarray(c.data) for c in m.cells}
    if path.suffix.lower() not in (".vtu", ".vtk"):
        raise ImportError(f"reading {path.suffix} files needs meshio (pip install meshio)")
    import pyvista

    grid = pyvista.read(path)
    cells = {("triangle" if k == pyvista.CellType.TRIANGLE else str(k)): np.asarray(v)
             for k, v in grid.cells_dict.items()}
    return np.asarray(grid.points, float), cells


def read_mesh(path: str | Path) -> TriangleMesh:
    """The linear triangles of a 2-D mesh file (z ≡ const. if present), oriented
    counter-clockwise, nodes no triangle uses dropped. InputError, one line, when the file
    cannot be read, holds no linear triangle, is not planar or has a degenerate triangle."""
    from pointatlas.errors import InputError

    path = Path(path)
    fix = "give a 2-D mesh of linear triangles (.msh from gmsh, .vtu) as physics.mesh_file"
    try:
        if not path.is_file():
            raise FileNotFoundError("no such file")
        points, cells = _read_cells(path)
    except (Exception, SystemExit) as exc:  # noqa: BLE001 - every failure is the user's file
        if isinstance(exc, SystemExit):       # meshio exits when no reader fits the file
            reason = "no reader recognises its content"
        else:
            text = str(exc).strip()
            reason = text.splitlines()[0] if text else type(exc).__name__
        raise InputError(f"physics.mesh_file={str(path)!r} cannot be read ({reason}); "
                         f"{fix}.") from None
    tri = cells.get("triangle")
    if tri is None or len(tri) == 0:
        raise InputError(f"physics.mesh_file={str(path)!r} holds no linear triangles (cells: "
                         f"{sorted(cells) or 'none'}); {fix}.")
    if points.ndim != 2 or points.shape[1] < 2:
        raise InputError(f"physics.mesh_file={str(path)!r} has points of shape {points.shape};"
                         f" {fix}.")
    extent = float(np.ptp(points[:, :2], axis=0).max()) or 1.0
    if points.shape[1] > 2 and np.ptp(points[:, 2]) > 1e-9 * extent:
        raise InputError(f"physics.mesh_file={str(path)!r} is not planar (z spans "
                         f"{np.ptp(points[:, 2]):.3g}); {fix}.")
    used, tri = np.unique(tri.astype(np.int64), return_inverse=True)
    mesh = TriangleMesh(np.ascontiguousarray(points[used, :2]), tri.reshape(-1, 3))
    area = mesh.areas
    if np.any(np.abs(area) <= 1e-12 * extent**2):
        k = int(np.argmin(np.abs(area)))
        raise InputError(f"physics.mesh_file={str(path)!r}: triangle {k} has zero area; "
                         f"remove degenerate triangles from the mesh.")
    flip = area < 0
    mesh.triangles[flip] = mesh.triangles[flip][:, [0, 2, 1]]
    return mesh


def clamped_nodes(nodes: np.ndarray, clamp) -> np.ndarray:
    """Boolean mask of the clamped nodes (both components fixed) selected by ``clamp``:

    * ``"bottom"``: the nodes with y ≤ min y + 10⁻⁹ × (size of the body);
    * ``{"y_below": c}``: the nodes with y ≤ c;
    * ``{"box": [xmin, ymin, xmax, ymax]}``: the nodes in that closed box.

    InputError (one line) when the selector picks fewer than two nodes (one clamped node
    leaves a rigid rotation free) or every node."""
    from pointatlas.errors import InputError

    check_clamp(clamp)
    x, y = nodes[:, 0], nodes[:, 1]
    if isinstance(clamp, str):
        size = float(np.ptp(nodes, axis=0).max())
        mask = y <= y.min() + 1e-9 * size
    elif "y_below" in clamp:
        mask = y <= float(clamp["y_below"])
    else:
        x0, y0, x1, y1 = (float(v) for v in clamp["box"])
        mask = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
    shown = dict(clamp) if isinstance(clamp, Mapping) else clamp
    n = int(mask.sum())
    span = (f"the nodes span x ∈ [{x.min():.4g}, {x.max():.4g}], y ∈ [{y.min():.4g}, "
            f"{y.max():.4g}]")
    if n < 2:
        raise InputError(f"physics.clamp={shown!r} selects {n} node(s) ({span}); clamp at least "
                         f"two nodes, e.g. physics.clamp=bottom.")
    if n == len(nodes):
        raise InputError(f"physics.clamp={shown!r} selects every node, so nothing can move; "
                         f"narrow it, e.g. physics.clamp=bottom.")
    return mask


def check_clamp(clamp) -> None:
    """ConfigError (one line) unless ``clamp`` is ``"bottom"``, ``{"y_below": number}`` or
    ``{"box": [xmin, ymin, xmax, ymax]}`` with xmin ≤ xmax, ymin ≤ ymax."""
    from pointatlas.errors import ConfigError

    example = "physics.clamp=bottom or physics.clamp={y_below: 0.01}"
    if isinstance(clamp, str):
        if clamp != "bottom":
            raise ConfigError(f"physics.clamp={clamp!r} is not a selector: use {example} or "
                              f"{{box: [xmin, ymin, xmax, ymax]}}.")
        return
    if not isinstance(clamp, Mapping) or len(clamp) != 1 or next(iter(clamp)) not in CLAMP_KEYS:
        raise ConfigError(f"physics.clamp={clamp!r} is not a selector: use {example} or "
                          f"{{box: [xmin, ymin, xmax, ymax]}} (one key of {CLAMP_KEYS}).")
    key, value = next(iter(clamp.items()))
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        v = np.array([np.nan])
    good = (v.shape == () if key == "y_below" else
            v.shape == (4,) and v[0] <= v[2] and v[1] <= v[3])
    if not good or not np.all(np.isfinite(v)):
        want = "a number" if key == "y_below" else "[xmin, ymin, xmax, ymax] with min ≤ max"
        raise ConfigError(f"physics.clamp={{{key}: {value!r}}} is invalid: {key} must be {want}.")
