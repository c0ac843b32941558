"""Energies as pointwise kernels of the local field jets (the kit's one physics contract).

A physics on the atlas is a total energy Π[U] = Σ_e Σ_q w_q W_e(jet_q, data_q), each
density W_e a function of the jets of the fields it declares (:mod:`.fields`: values and
chart derivatives at a quadrature point) and of per-point data (reference geometry,
material, sources), with weights w_q of the atlas quadrature (thesis Eq. 14). An energy is
a small class with metadata as attributes and two methods:

``fields``          the :class:`~.fields.Field` objects its density depends on;
``density_names``   names of the parts of the density it reports (their sum is W_e);
``frame_invariant`` True when W_e is unchanged by rigid motions of a 3-component field
                    (the conformance suite then checks zero energy and residual for them);
``point_data(quadrature)``   (m, n_data) float64, computed once per quadrature;
``evaluate(jets, data, want)``  for jets (n, n_jet) and data (n, n_data) returns
                    (dens (n, n_parts), g (n, n_jet) or None, H (n, n_jet, n_jet) or None):
                    g = ∂W/∂jet if want ≥ 1, H = ∂²W/∂jet² (symmetric) if want ≥ 2.

The jet layout is that of a :class:`~.fields.FieldLayout` of the energy's own fields in
its order. Kernels are pure functions on arrays (numba where hot); external work (loads)
is an energy too, linear in the jets.
"""
from __future__ import annotations

from typing import ClassVar, Optional, Protocol, runtime_checkable

import numpy as np

from pointatlas.errors import ConfigError

from .fields import Field


@runtime_checkable
class Energy(Protocol):
    fields: tuple[Field, ...]
    density_names: tuple[str, ...]
    frame_invariant: bool

    def point_data(self, quadrature) -> np.ndarray: ...

    def evaluate(self, jets: np.ndarray, data: np.ndarray, want: int
                 ) -> tuple[np.ndarray, Optional[np.ndarray], Optional[np.ndarray]]: ...


class LinearSource:
    """External work −∫ s · u dΓ of a field's values (a dead load or a source term), as an
    energy: W = −s(x_q) · u_q with s given per point (units of the field's work density).

    ``values`` (m, components): s at the quadrature points.
    """

    density_names: ClassVar[tuple[str, ...]] = ("external_work",)
    frame_invariant: ClassVar[bool] = False

    def __init__(self, field: Field, values):
        if not field.value:
            raise ConfigError(f"a source on field {field.name!r} needs its value in the jet "
                              "(value=True).")
        self.fields = (field,)
        self.field = field
        self.values = np.ascontiguousarray(values, dtype=np.float64).reshape(-1, field.components)

    def point_data(self, quadrature) -> np.ndarray:
        if len(self.values) != quadrature.n_points:
            raise ConfigError(f"the source of field {self.field.name!r} has "
                              f"{len(self.values)} values; the quadrature has "
                              f"{quadrature.n_points} points.")
        return self.values

    def evaluate(self, jets, data, want):
        c = self.field.components
        u = jets[:, :c]          # column 0 (the value) comes first in the jet
        dens = -(u * data).sum(axis=1)[:, None]
        g = H = None
        if want >= 1:
            g = np.zeros_like(jets)
            g[:, :c] = -data
        if want >= 2:
            H = np.zeros((len(jets), jets.shape[1], jets.shape[1]))
        return dens, g, H


class DiscreteEnergy:
    """Energies assembled on quadrature arrays (the conformance suite's view of a physics,
    :mod:`pointatlas.physics_conformance`): energy, residual, tangent, rigid motions."""

    def __init__(self, fields, energies, patch: dict):
        from .assembler import Assembler
        from .atlas_quadrature import AtlasQuadrature
        from .fields import FieldLayout

        arrays = {k: v for k, v in patch.items() if k != "node_positions"}
        q = AtlasQuadrature(**arrays)
        self.layout = FieldLayout(fields, q.n_nodes)
        self.assembler = Assembler(q, self.layout, energies)
        self.node_positions = np.asarray(patch["node_positions"], dtype=np.float64)
        self.frame_invariant = bool(energies) and all(e.frame_invariant for e in energies)
        self.n_dofs = self.layout.n_dofs

    def energy(self, U) -> float:
        return self.assembler.energy(U)["total"]

    def residual(self, U):
        return self.assembler.residual(U)

    def tangent(self, U):
        return self.assembler.tangent(U)

    def rigid_motion(self, R, t) -> np.ndarray:
        """U of the finite rigid motion x ↦ R x + t on the first 3-component field."""
        f = next(f for f in self.layout.fields if f.components == 3)
        U = np.zeros((self.layout.n_nodes, self.layout.block))
        o = self.layout.offsets[f.name]
        P = self.node_positions
        U[:, o:o + 3] = P @ np.asarray(R).T + np.asarray(t) - P
        return U.ravel()
