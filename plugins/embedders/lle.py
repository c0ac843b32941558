"""Locally linear embedding (Roweis & Saul 2000; thesis §2.2), via scikit-learn.

The embedding is scaled to unit covariance, (1/N) sum_a y_a y_a^T = I, the LLE constraint the
thesis uses (L1873: "subject to (1/N) Xi Xi^T = I ... unit covariance"; also L86, L139, L144 for
MLLE); sklearn returns unit-norm eigenvectors, times sqrt(N). Its metric is arbitrary, hence AIC.

Regularisation: the thesis does not state one (it only notes the ill-conditioned weight problem,
L1873). With k = 12 > D = 3 neighbours the local Gram matrix C is singular and must be
regularised; ``reg`` adds reg * trace(C) to its diagonal, the convention of Roweis & Saul's
reference code (tol = 1e-3 when k > D) and of scikit-learn, hence the default 1e-3. On the
Table 1 set (N = 700) E_S after AIC is 92.8 for reg = 1e-3, 98.1 for 1e-4, 121 for 1e-2
(thesis: 96.5); 'arpack' and 'dense' eigensolvers give the same embedding.

Out of sample (``transform``, :func:`.out_of_sample.lle_extension`): a new x is written as
x ~ sum_j w_j x_j over its ``n_neighbors`` nearest training points (the same regularised weights
as the fit) and mapped to y = sum_j w_j y_j (Saul & Roweis 2003, §6.1). A training point is
reconstructed from its own LLE neighbourhood, so ``transform`` reproduces the embedding up to
the LLE residual y_i - sum_j W_ij y_j (on the 800-point swiss roll of the tests, k = 12: at most
0.004, RMS 4e-4, of the unit-covariance coordinates; MLLE 0.006 and 6e-4). The same weights place
new points, y = sum_j w_j y_j (for MLLE too: its embedding is close to an affine image of the
manifold's coordinates, which barycentric weights reproduce).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

import numpy as np

from pointatlas.constraints import Interval, Options
from pointatlas.errors import ConfigError

from .base import EmbedderBase
from .checks import AIC, COMPONENTS, check_components, check_points
from .neighbor_graph import connected_neighbor_graph
from .out_of_sample import lle_extension


@dataclass
class LLEConfig:
    n_components: int = 2            # below the ambient dimension (checked in fit)
    n_neighbors: int = 12            # >= n_components + 1
    reg: float = 1e-3                # reg * trace(C) added to the local Gram matrix
    eigen_solver: str = "auto"
    random_state: Optional[int] = 0  # seed of the arpack start vector (numpy's seed range)
    aic: bool = False
    aic_neighbors: Optional[int] = None

    parameter_constraints: ClassVar[dict[str, list]] = {
        **COMPONENTS, **AIC,
        "n_neighbors": [Interval(int, 1, None)],
        "reg": [Interval(float, 0, None, closed="neither")],
        "eigen_solver": [Options(("auto", "arpack", "dense"))],
        "random_state": [Interval(int, 0, 2**32 - 1), None],
    }


class LLEBase(EmbedderBase):
    """sklearn ``LocallyLinearEmbedding`` with method ``_method``; checks and errors of our own."""

    _method: ClassVar[str] = "standard"

    def _min_neighbors(self, d: int) -> int:
        return d + 1

    def _check_settings(self) -> None:
        d, k = self.n_components, self.n_neighbors
        if k < self._min_neighbors(d):
            raise ConfigError(
                f"n_components={d} is too large for n_neighbors={k}: {self._method} LLE needs "
                f"n_neighbors >= {self._min_neighbors(d)}. Raise n_neighbors or lower n_components."
            )

    def _embed(self, X) -> np.ndarray:
        from scipy.spatial import cKDTree
        from sklearn.manifold import LocallyLinearEmbedding

        k = int(self.n_neighbors)
        d = check_components(self.n_components, X, method=f"{self._method} LLE")
        X = check_points(X, min_points=k + 1, reason=f" for n_neighbors={k}")
        connected_neighbor_graph(X, k)
        model = LocallyLinearEmbedding(
            n_neighbors=k, n_components=d, reg=self.reg, eigen_solver=self.eigen_solver,
            method=self._method, random_state=self.random_state, **self._extra())
        # sklearn returns unit-norm eigenvectors; the thesis' LLE has unit covariance (§2.2)
        Y = model.fit_transform(X) * np.sqrt(X.shape[0])
        self.reconstruction_error_ = float(model.reconstruction_error_)
        self.tree_ = cKDTree(X)
        return Y

    def _extend(self, X: np.ndarray) -> np.ndarray:
        """Barycentric LLE extension (module docstring) of ``embedding_raw_``."""
        return lle_extension(self.embedding_raw_, self.tree_, X, int(self.n_neighbors),
                             float(self.reg))

    def _extra(self) -> dict:
        return {}


class LLE(LLEBase):
    """Standard LLE, optionally followed by AIC."""

    Config: ClassVar[type] = LLEConfig
    description: ClassVar[str] = "Locally linear embedding (standard LLE, scikit-learn)."
    _method: ClassVar[str] = "standard"

    def __init__(self, *, n_components: int = 2, n_neighbors: int = 12, reg: float = 1e-3,
                 eigen_solver: str = "auto", random_state: Optional[int] = 0, aic: bool = False,
                 aic_neighbors: Optional[int] = None):
        self.n_components = n_components
        self.n_neighbors = n_neighbors
        self.reg = reg
        self.eigen_solver = eigen_solver
        self.random_state = random_state
        self.aic = aic
        self.aic_neighbors = aic_neighbors
