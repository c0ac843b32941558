"""Modified locally linear embedding (Zhang & Wang 2007; thesis §2.2), via scikit-learn.

``transform`` is LLE's barycentric extension (:mod:`.lle`, :func:`.out_of_sample.lle_extension`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Optional

from pointatlas.constraints import Interval

from .lle import LLEBase, LLEConfig


@dataclass
class MLLEConfig(LLEConfig):
    """LLE's settings plus the tolerance of the modified (multiple-weights) variant."""

    modified_tol: float = 1e-12

    parameter_constraints: ClassVar[dict[str, list]] = {
        **LLEConfig.parameter_constraints,
        "modified_tol": [Interval(float, 0, None, closed="neither")],
    }


class MLLE(LLEBase):
    """Modified LLE (multiple local weights), optionally followed by AIC (thesis Fig. 6G)."""

    Config: ClassVar[type] = MLLEConfig
    description: ClassVar[str] = "Modified locally linear embedding (MLLE, scikit-learn)."
    _method: ClassVar[str] = "modified"

    def __init__(self, *, n_components: int = 2, n_neighbors: int = 12, reg: float = 1e-3,
                 modified_tol: float = 1e-12, eigen_solver: str = "auto",
                 random_state: Optional[int] = 0, aic: bool = False,
                 aic_neighbors: Optional[int] = None):
        self.n_components = n_components
        self.n_neighbors = n_neighbors
        self.reg = reg
        self.modified_tol = modified_tol
        self.eigen_solver = eigen_solver
        self.random_state = random_state
        self.aic = aic
        self.aic_neighbors = aic_neighbors

    def _min_neighbors(self, d: int) -> int:
        return d + 1

    def _extra(self) -> dict:
        return {"modified_tol": self.modified_tol}
