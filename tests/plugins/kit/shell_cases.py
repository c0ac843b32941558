"""Kit quadratures made from the shell tests' small LME patches (no atlas needed)."""
import numpy as np

from pointatlas_kit.atlas_quadrature import AtlasQuadrature


def kit_quadrature(sq) -> AtlasQuadrature:
    """The :class:`AtlasQuadrature` holding the same points as a ShellQuadrature ``sq``."""
    ref = sq.reference
    S = np.stack([np.stack([ref[:, 2], ref[:, 3]], 1), np.stack([ref[:, 3], ref[:, 4]], 1)], 1)
    m = sq.n_points
    return AtlasQuadrature(indptr=sq.indptr, indices=sq.indices, basis=sq.basis,
                           weights=sq.weights, chart=sq.group, positions=np.zeros((m, 3)),
                           tangents=ref[:, :2].copy(), second=S, orientation=np.ones(m),
                           n_nodes=sq.n_nodes)
