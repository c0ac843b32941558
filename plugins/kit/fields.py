"""Fields on an atlas as declared metadata, and the kit's DOF numbering of several fields.

A field u = Σ_a p_a(ξ) U_a (thesis Eq. 2, §3.3) has ``components`` values per node and
an energy that needs its chart derivatives up to ``order`` (0: values; 1: + ∂_α; 2: + ∂_αβ,
with ∂_12 symmetrised). All fields of one physics share the atlas basis p_a, so the DOFs are
numbered node by node: node a holds the block of B = Σ_f components_f DOFs

    dof(f, a, i) = B a + offset_f + i,

which for the shell alone (B = 3) is the familiar 3a + i.

The **jet** of the fields at a quadrature point is the vector the energy kernel sees: field
after field, each an (n_columns_f, components_f) block flattened row by row,

    jet[jet_offset_f + k components_f + i] = Σ_a p_a,c(k) U_(a, offset_f + i),

where c(k) runs over the basis columns the field uses (:data:`BASIS_COLUMNS`; a field with
``value=False`` skips column 0, e.g. the shell's displacement, whose energy depends only on
derivatives).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from pointatlas.errors import ConfigError

#: Columns of the basis at a quadrature point: p, ∂_1 p, ∂_2 p, ∂_11 p, ∂_12 p, ∂_22 p.
BASIS_COLUMNS = ("p", "p_1", "p_2", "p_11", "p_12", "p_22")
#: Number of basis columns needed for derivative order 0, 1, 2 (2-d charts).
COLUMNS_FOR_ORDER = {0: 1, 1: 3, 2: 6}


@dataclass(frozen=True)
class Field:
    """A field on the atlas: ``name``, ``components`` per node, derivative ``order`` its
    energy needs (0, 1 or 2) and whether the energy uses its ``value`` (column 0)."""

    name: str
    components: int
    order: int
    value: bool = True
    units: str = "1"
    long_name: str = ""

    def __post_init__(self):
        if not self.name.isidentifier():
            raise ConfigError(f"field name {self.name!r} must be an identifier (letters, "
                              "digits, underscores), e.g. 'displacement'.")
        if not (isinstance(self.components, int) and self.components >= 1):
            raise ConfigError(f"field {self.name!r}: components = {self.components!r} must be "
                              "an integer >= 1.")
        if self.order not in COLUMNS_FOR_ORDER:
            raise ConfigError(f"field {self.name!r}: order = {self.order!r} must be 0, 1 or 2 "
                              "(the highest chart derivative its energy needs).")
        if not self.value and self.order == 0:
            raise ConfigError(f"field {self.name!r} has order 0 and value=False: it would "
                              "enter no energy. Use value=True or a higher order.")

    @property
    def columns(self) -> tuple[int, ...]:
        """The basis columns (indices into :data:`BASIS_COLUMNS`) of this field's jet."""
        return tuple(range(0 if self.value else 1, COLUMNS_FOR_ORDER[self.order]))

    @property
    def jet_size(self) -> int:
        return len(self.columns) * self.components


class FieldLayout:
    """DOF numbering and jet layout of several fields on ``n_nodes`` atlas nodes."""

    def __init__(self, fields: Sequence[Field], n_nodes: int):
        fields = tuple(fields)
        if not fields:
            raise ConfigError("a physics needs at least one field.")
        names = [f.name for f in fields]
        if len(set(names)) != len(names):
            raise ConfigError(f"field names must be unique; got {names}.")
        self.fields = fields
        self.n_nodes = int(n_nodes)
        self.block = sum(f.components for f in fields)
        self.order = max(f.order for f in fields)
        self.offsets = dict(zip(names, np.cumsum([0] + [f.components for f in fields])[:-1]
                                .tolist()))
        self.jet_offsets = dict(zip(names, np.cumsum([0] + [f.jet_size for f in fields])[:-1]
                                    .tolist()))
        self.jet_size = sum(f.jet_size for f in fields)
        col, dof = [], []
        for f in fields:
            for c in f.columns:
                for i in range(f.components):
                    col.append(c)
                    dof.append(self.offsets[f.name] + i)
        #: basis column and in-block DOF of every jet entry (the assembler's tables)
        self.jet_column = np.asarray(col, np.int64)
        self.jet_dof = np.asarray(dof, np.int64)
        #: per field: first basis column, columns, components, DOF offset, jet offset
        self.field_tables = tuple(np.asarray(v, np.int64) for v in zip(*[
            (f.columns[0], len(f.columns), f.components, self.offsets[f.name],
             self.jet_offsets[f.name]) for f in fields]))

    @property
    def n_dofs(self) -> int:
        return self.block * self.n_nodes

    def field(self, name: str) -> Field:
        for f in self.fields:
            if f.name == name:
                return f
        raise ConfigError(f"no field named {name!r}; the fields are "
                          f"{[f.name for f in self.fields]}.")

    def dofs(self, name: str, nodes, components=None) -> np.ndarray:
        """Global DOF ids of field ``name`` at ``nodes`` (k,) for ``components`` (default
        all): shape (k, n_components)."""
        f = self.field(name)
        comps = range(f.components) if components is None else components
        comps = np.asarray(list(comps), np.int64)
        if comps.size and (comps.min() < 0 or comps.max() >= f.components):
            raise ConfigError(f"field {name!r} has components 0..{f.components - 1}; got "
                              f"{comps.tolist()}.")
        nodes = np.asarray(nodes, np.int64)
        return self.block * nodes[:, None] + self.offsets[name] + comps[None, :]

    def split(self, U) -> dict[str, np.ndarray]:
        """The DOF vector (n_dofs,) as {name: (n_nodes, components)} views."""
        U = self.as_blocks(U)
        return {f.name: U[:, self.offsets[f.name]:self.offsets[f.name] + f.components]
                for f in self.fields}

    def as_blocks(self, U) -> np.ndarray:
        """U as a contiguous (n_nodes, block) float64 array (from (n_dofs,) or 2-d)."""
        U = np.ascontiguousarray(U, dtype=np.float64)
        if U.shape == (self.n_dofs,):
            U = U.reshape(self.n_nodes, self.block)
        if U.shape != (self.n_nodes, self.block):
            from pointatlas.errors import InputError

            raise InputError(f"nodal values have shape {U.shape}; expected ({self.n_nodes}, "
                             f"{self.block}) or ({self.n_dofs},).")
        if not np.all(np.isfinite(U)):
            from pointatlas.errors import InputError

            raise InputError("nodal values contain NaN or inf.")
        return U

    def jet_slice(self, name: str) -> slice:
        f = self.field(name)
        o = self.jet_offsets[name]
        return slice(o, o + f.jet_size)
