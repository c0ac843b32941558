"""Supports on any field: prescribed values of chosen components on selected points.

A support holds components i of field f at the points x_k a selector picks (thesis App.
E.2: constraints C U = g, imposed by the augmented Lagrangian of
:mod:`pointatlas_solvers.augmented_lagrangian`):

    u_i(x_k) = Σ_b p_b(ξ_k) U_(b, f, i) = g_ki.

Shell-specific rows (clamping, symmetry of the normal) are the shell's; this is the part
every field shares.
"""
from __future__ import annotations

import numpy as np
from scipy.sparse import csr_matrix

from pointatlas.errors import ConfigError, InputError


def value_constraints(atlas, layout, field: str, nodes, values, components=None):
    """(C (k·c, n_dofs) csr, g (k·c,)) holding ``components`` (default all) of ``field`` at
    control points ``nodes`` (k,) to ``values`` (k, c) or a scalar."""
    from pointatlas_atlas.evaluation import basis_at_nodes

    f = layout.field(field)
    comps = list(range(f.components)) if components is None else list(components)
    nodes = np.asarray(nodes, np.int64)
    if nodes.size == 0:
        raise InputError(f"a support on field {field!r} selects no point: check its 'where'.")
    dofs = layout.dofs(field, np.arange(layout.n_nodes), comps)  # ConfigError if bad comps
    g = np.broadcast_to(np.asarray(values, dtype=np.float64), (nodes.size, len(comps)))
    if not np.all(np.isfinite(g)):
        raise ConfigError(f"the values of a support on field {field!r} must be finite.")
    basis, _, _ = basis_at_nodes(atlas, nodes, order=0)
    B = basis.to_csr(layout.n_nodes).tocoo()
    rows, cols, vals = [], [], []
    for j in range(len(comps)):
        rows.append(B.row * len(comps) + j)
        cols.append(dofs[B.col, j])
        vals.append(B.data)
    C = csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                   shape=(nodes.size * len(comps), layout.n_dofs))
    return C, np.ascontiguousarray(g).ravel()
