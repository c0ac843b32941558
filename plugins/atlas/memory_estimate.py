"""Memory a computation will need, estimated from its sizes before it starts, and the memory
the process may still use; a request that cannot fit is refused in one line.

All sizes are in bytes (float64 and int64 entries: 8 bytes). The estimates count the arrays
that live until the end of the computation, term by term (see each docstring); they are
checked against measured peaks in tests/plugins/atlas/test_memory_estimate.py (within a
factor of 2). Counts of neighbours come from the Gaussian cut-off of the approximants:
node a supports x when exp(-β_a |x - x_a|²) > tol with β_a = γ / h_a² (thesis Box 2), i.e.
|x - x_a| < h_a sqrt(ln(1/tol) / γ).
"""
from __future__ import annotations

import math
import resource
from pathlib import Path

from pointatlas.errors import InputError

#: bytes of one float64 or int64 entry
WORD = 8

#: quadrature redundancy (Gauss points kept / those of one cover) assumed by the estimate:
#: the default sphere atlas measures 1.57 (5 000 to 40 000 points, markers_per_patch 150);
#: smaller patches overlap more, hence the margin.
DEFAULT_REDUNDANCY = 2.0

#: d-simplices per point of a triangulation of a closed d-manifold: N segments on a curve,
#: 2N triangles on a surface (Euler), about 6.5N tetrahedra in 3-D (Delaunay of random points)
SIMPLICES_PER_POINT = {1: 1.0, 2: 2.0, 3: 6.5}


def ball_volume(d: int) -> float:
    """Volume ω_d of the unit d-ball, π^(d/2) / Γ(d/2 + 1)."""
    return math.pi ** (d / 2) / math.gamma(d / 2 + 1)


def support_size(intrinsic_dim: int, gamma: float, tol: float) -> float:
    """Nodes in the support of a Gaussian weight on a d-manifold sampled at spacing h:
    ω_d (ln(1/tol) / γ)^(d/2) (one node per h^d; radius h sqrt(ln(1/tol)/γ), thesis Box 2).

    LME charts (γ = 0.8, tol = 1e-10) on a surface: 90 nodes; the Shepard partition of unity
    (γ = 4, tol = 1e-6): 11 markers.
    """
    return ball_volume(intrinsic_dim) * (math.log(1.0 / tol) / gamma) ** (intrinsic_dim / 2)


def grid_entries_per_node(dim: int) -> float:
    """Cells of the approximants' SupportGrid a node's support ball is registered in.

    The grid (pointatlas_approximants.support.SupportGrid) has cells of side c·r (c = 0.35 for
    dim = 2, 0.25·dim otherwise, r the median radius) in the space the nodes live in; a
    ball's bounding box spans 2/c + 1 cells per axis: (2/c + 1)^dim.
    """
    c = 0.35 if dim == 2 else 0.25 * dim
    return (2.0 / c + 1.0) ** dim


def estimate_atlas_bytes(n_points: int, ambient_dim: int, intrinsic_dim: int,
                         support_size: float, *, pu_support_size: float,
                         quadrature_order: int = 6, rule_size: int | None = None,
                         n_markers: int | None = None, margin: float = 3.0,
                         redundancy: float = DEFAULT_REDUNDANCY, second_derivatives: bool = True,
                         keep_basis: bool = False) -> int:
    """Bytes an atlas of ``n_points`` points holds once its charts and quadrature are built.

    N points in R^D on a d-manifold; ``support_size`` s: LME nodes per evaluation point
    (:func:`support_size`); ``pu_support_size``: markers per point of the Shepard partition of
    unity; ``margin``: chart margin in spacings. Terms (8-byte words):

    * Gauss points n_g = redundancy · (simplices per point) · (rule size) · N, each holding,
      in its chart and again in the atlas-wide arrays, the weight, ψ, J, chart index, ξ (d),
      φ (D), ∂φ (dD), ∂²φ (d²D), and the geometry (metric and second form d² each, normal
      D, principal curvatures d, H, K, area element): 2(D + dD + d²D) + d + 5 + 2d² + D + d + 3;
      with ``keep_basis`` also the basis (s values, s·d first and s·d(d+1)/2 second
      derivatives, s node indices).
    * points: the coordinates and their k-d tree, 3D; the partition of unity at the points
      in two sparse layouts, 4·(PU support); the margin neighbours, ω_d margin^d;
    * control points (≈ redundancy · N): ξ, P (d + D) and their LME support grid,
      (d + 2) · (cells per node, :func:`grid_entries_per_node` (d));
    * markers M (default N): the PU support grid in R^D, (D + 2) · cells per node (D).

    Returns the estimate in bytes.
    """
    N, D, d = int(n_points), int(ambient_dim), int(intrinsic_dim)
    M = N if n_markers is None else int(n_markers)
    if rule_size is None:
        from .quadrature import simplex_rule

        rule_size = simplex_rule(d, quadrature_order).n_points
    simplices = SIMPLICES_PER_POINT.get(d, float(math.factorial(d)))
    n_gauss = redundancy * simplices * rule_size * N
    second = d * d * D if second_derivatives else 0
    per_gauss = 2 * (D + d * D + second) + d + 5 + 2 * d * d + D + d + 3
    if keep_basis:
        per_gauss += support_size * (2 + d + (d * (d + 1) // 2 if second_derivatives else 0))
    per_point = 3 * D + 4 * pu_support_size + ball_volume(d) * margin ** d
    per_control = d + D + (d + 2) * grid_entries_per_node(d)
    per_marker = D + (D + 2) * grid_entries_per_node(D)
    words = n_gauss * per_gauss + N * per_point + redundancy * N * per_control + M * per_marker
    return int(words * WORD)


#: copies of the tangent's entries alive at once in a linear solve: the assembled blocks,
#: their CSR form, K + ρCᵀC and about one more for the sparse factor (measured on the
#: hemisphere shell, 2 000 and 4 000 points: tests/plugins/atlas/test_memory_estimate.py)
TANGENT_COPIES = 4


def estimate_tangent_bytes(n_nodes: int, block: int, support_size: float,
                           copies: float = TANGENT_COPIES) -> int:
    """Bytes of a physics' sparse tangent and its solve on ``n_nodes`` atlas nodes with
    ``block`` DOFs each: two nodes couple when their supports (radius r, ``support_size``
    s = π r² nodes on a surface) overlap, so about 4 s neighbours a node; each coupling is a
    block × block set of entries of 12 bytes (value and column index), ``copies`` times."""
    return int(n_nodes * 4.0 * support_size * block * block * 12 * copies)


def estimate_dense_embedding_bytes(n_points: int) -> int:
    """Bytes of an embedding through an N x N matrix (Isomap's geodesic distances, classical
    MDS in place): 8 N²."""
    return WORD * int(n_points) ** 2


def available_memory_bytes() -> tuple[int, str]:
    """Bytes this process may still allocate, and which limit sets it.

    The least of: the address-space limit (RLIMIT_AS soft limit minus the address space in
    use, ``ulimit -v``), the cgroup limit (memory.max minus memory.current, cgroup v2), and
    the machine's MemAvailable (/proc/meminfo). Limits that do not exist are skipped; with
    none readable, (sys.maxsize, 'no limit found').
    """
    import sys

    found = []
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft != resource.RLIM_INFINITY:
        used = (_proc_kib("/proc/self/status", "VmSize") or 0) * 1024
        found.append((max(soft - used, 0), f"the address-space limit (ulimit -v {soft // 1024})"))
    cgroup = _cgroup_free()
    if cgroup is not None:
        found.append((cgroup, "the cgroup memory limit (memory.max)"))
    meminfo = _proc_kib("/proc/meminfo", "MemAvailable")
    if meminfo is not None:
        found.append((meminfo * 1024, "the memory available on this machine (MemAvailable)"))
    return min(found) if found else (sys.maxsize, "no limit found")


def check_memory(needed: int, what: str, fix: str) -> None:
    """Refuse, in one :class:`InputError` line, a computation of ``needed`` bytes that does
    not fit :func:`available_memory_bytes`; ``what`` names it, ``fix`` says what to change."""
    available, limit = available_memory_bytes()
    if needed > available:
        raise InputError(f"{what} needs about {format_bytes(needed)} of memory, but only "
                         f"{format_bytes(available)} is available ({limit}). {fix}")


def format_bytes(n: float) -> str:
    """``n`` bytes with a binary unit: '7.28 TiB'."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if abs(n) < 1024 or unit == "TiB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.2f} {unit}"
        n /= 1024
    raise AssertionError("unreachable")


def _proc_kib(path: str, key: str) -> int | None:
    """A 'kB' field (``key: N kB``) of a /proc file; None where there is no such field."""
    try:
        for line in Path(path).read_text().splitlines():
            if line.startswith(key + ":"):
                return int(line.split()[1])
    except (OSError, ValueError, IndexError):
        pass
    return None


def _cgroup_free() -> int | None:
    """memory.max - memory.current of this process's cgroup (v2), or None without a limit."""
    try:
        rel = Path("/proc/self/cgroup").read_text().strip().splitlines()[0].split("::", 1)[1]
        base = Path("/sys/fs/cgroup") / rel.lstrip("/")
        limit = (base / "memory.max").read_text().strip()
        if limit == "max":
            return None
        return max(int(limit) - int((base / "memory.current").read_text().strip()), 0)
    except (OSError, ValueError, IndexError):
        return None


def check_atlas_memory(atlas, n_points: int, n_markers: int, ambient_dim: int,
                       keep_basis: bool, extra_bytes: int = 0, extra_what: str = "",
                       extra_fix: str = "") -> None:
    """Refuse, before any work, an atlas (with ``extra_bytes`` of what is computed on it,
    e.g. a physics' tangent) that cannot fit in memory (one line, with fix; ``extra_fix``
    one more way out the caller offers)."""
    needed = atlas.estimated_bytes(n_points, n_markers, ambient_dim, atlas.chart_dim_,
                                   keep_basis) + int(extra_bytes)
    available, _ = available_memory_bytes()
    # the estimate is linear in N; the suggested size leaves 10 % of the memory free
    fitting = max(1, int(n_points * min(1.0, available / max(needed, 1)) * 0.9))
    check_memory(
        needed, f"an atlas of {n_points} points in R^{ambient_dim} (charts of dimension "
                f"{atlas.chart_dim_}, quadrature order {atlas.settings.quadrature_order})"
                + (f" with {extra_what}" if extra_what else ""),
        f"Use fewer points (e.g. source.n_points={fitting}, memory grows in proportion), a "
        "lower study.quadrature_order, " + (f"{extra_fix}, " if extra_fix else "")
        + "or a machine with more memory.")
