"""Physics plugin ``neo_hookean_2d``: plane-strain compressible neo-Hookean elastodynamics on
linear triangles, explicit in time: the full model of Lagrangian model reduction (Millán
2012 §5.2; Millán & Arroyo, CMAME 261–262 (2013) 118–131; issue 21).

``solve(ctx, *, x0=None, v0=None, n_steps=None)`` integrates M ẍ = m g − f_int(x) with the
clamped nodes fixed (:mod:`.integrator`) and returns a Dataset (:mod:`.results`) of positions,
displacements and velocities over the saved steps (dims ``time``, ``node``, ``dim``), the
kinetic, elastic, gravity, potential and total energies, and the UGRID mesh.

Initial state, unless ``x0`` (n, 2) / ``v0`` (n, 2) are given:

* positions: the reference X, or with ``initial_load = [b_x, b_y]`` the static equilibrium
  (:mod:`.statics`) under the body force ρ b (b in length / time²), released at t = 0 under
  ``gravity`` (e.g. ``initial_load: [0.5, -1]`` swings the column sideways);
* velocities: v(X) = v₀ + L (X − X_c), ``initial_velocity`` v₀ (length / time) and
  ``initial_velocity_gradient`` L = [[L_xx, L_xy], [L_yx, L_yy]] given row by row as four
  numbers (1 / time), X_c the centroid of the clamped nodes; zero on the clamped nodes.
  ``[0, 1, 0, 0]`` is a sway v_x = (y − y_c).

Units are any consistent set (length, time, mass); the body is per unit thickness.
The Config defaults are the thesis' (λ = 1000, μ = 500, ρ = 1, Δt = 2·10⁻⁵, a body of about
9 400 triangles clamped at the bottom under unit gravity); the body is a stand-in
(:func:`.mesh.tapered_column`) unless ``mesh_file`` is given.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar, List, Optional

import numpy as np

from pointatlas.constraints import Each, Interval, Options, Types
from pointatlas.stores_config import stores_config

_NUMBER = Interval(float)


@dataclass
class NeoHookean2DConfig:
    """Lamé λ and μ (force / length², μ > 0, λ + μ > 0), density ρ (mass / length³), gravity
    g (length / time²); ``mass`` lumped or consistent; time step ``dt``, ``n_steps``, a state
    saved every ``save_every`` steps; ``clamp``: ``bottom``, ``{y_below: c}`` or ``{box:
    [xmin, ymin, xmax, ymax]}``; the stand-in column (``height``, ``base_width``,
    ``top_width``, about ``n_triangles`` triangles) or ``mesh_file`` (.msh, .vtu); initial
    state (module doc); ``static_tol``: relative residual of the static solve."""

    lam: float = 1000.0
    mu: float = 500.0
    density: float = 1.0
    gravity: List[float] = field(default_factory=lambda: [0.0, -1.0])
    mass: str = "lumped"
    dt: float = 2.0e-5
    n_steps: int = 10000
    save_every: int = 100
    clamp: Any = "bottom"
    height: float = 1.5
    base_width: float = 0.24
    top_width: float = 0.08
    n_triangles: int = 9428
    mesh_file: Optional[str] = None
    initial_load: Optional[List[float]] = None
    initial_velocity: List[float] = field(default_factory=lambda: [0.0, 0.0])
    initial_velocity_gradient: List[float] = field(default_factory=lambda: [0.0, 0.0, 0.0, 0.0])
    static_tol: float = 1.0e-10
    parameter_constraints: ClassVar[dict] = {
        "lam": [_NUMBER],
        "mu": [Interval(float, 0, None, closed="neither")],
        "density": [Interval(float, 0, None, closed="neither")],
        "gravity": [Each(_NUMBER, length=2)],
        "mass": [Options(("lumped", "consistent"))],
        "dt": [Interval(float, 0, None, closed="neither")],
        "n_steps": [Interval(int, 0, None)],
        "save_every": [Interval(int, 1, None)],
        "clamp": [Types(str, dict)],
        "height": [Interval(float, 0, None, closed="neither")],
        "base_width": [Interval(float, 0, None, closed="neither")],
        "top_width": [Interval(float, 0, None, closed="neither")],
        "n_triangles": [Interval(int, 2, 10**8)],
        "mesh_file": [Types(str), None],
        "initial_load": [Each(_NUMBER, length=2), None],
        "initial_velocity": [Each(_NUMBER, length=2)],
        "initial_velocity_gradient": [Each(_NUMBER, length=4)],
        "static_tol": [Interval(float, 0, 1, closed="neither")]}


@stores_config
class NeoHookean2D:
    """Compressible neo-Hookean body in plane strain, linear triangles, explicit dynamics."""

    Config = NeoHookean2DConfig
    description: ClassVar[str] = ("2-D plane-strain neo-Hookean elastodynamics on linear "
                                  "triangles (explicit Verlet), clamped, under gravity.")

    def check_config(self) -> None:
        """The rules tying settings together: a positive plane-strain bulk modulus λ + μ and a
        well-formed clamp selector (ConfigError, one line)."""
        from pointatlas.errors import ConfigError

        from .mesh import check_clamp

        if not self.lam + self.mu > 0:
            raise ConfigError(f"physics.lam + physics.mu = {self.lam + self.mu:g} must be > 0 "
                              f"(the plane-strain bulk modulus); raise physics.lam, e.g. "
                              f"physics.lam=1000.0.")
        check_clamp(_plain(self.clamp))

    def build_body(self):
        """The :class:`~.body.ElasticBody` of these settings (mesh, clamps, material)."""
        from .body import ElasticBody
        from .mesh import clamped_nodes, read_mesh, tapered_column

        if self.mesh_file is not None:
            mesh = read_mesh(self.mesh_file)
        else:
            mesh = tapered_column(self.height, self.base_width, self.top_width,
                                  self.n_triangles)
        return ElasticBody(mesh, float(self.lam), float(self.mu), float(self.density),
                           np.asarray(self.gravity, float),
                           clamped_nodes(mesh.nodes, _plain(self.clamp)))

    def initial_positions(self, body) -> np.ndarray:
        """x0 (n, 2): the reference X, or the static equilibrium under ρ ``initial_load``."""
        from .statics import static_equilibrium

        if self.initial_load is None:
            return body.reference.copy()
        load = body.nodal_masses[:, None] * np.asarray(self.initial_load, float)[None, :]
        return static_equilibrium(body, load=load, tol=self.static_tol).x

    def initial_velocities(self, body) -> np.ndarray:
        """v0 (n, 2) = v₀ + L (X − X_c), zero on the clamped nodes (module doc)."""
        X = body.reference
        L = np.asarray(self.initial_velocity_gradient, float).reshape(2, 2)
        centre = X[body.clamped].mean(axis=0)
        v0 = np.asarray(self.initial_velocity, float)[None, :] + (X - centre) @ L.T
        v0[body.clamped] = 0.0
        return v0

    def solve(self, ctx, *, x0=None, v0=None, n_steps: int | None = None):
        """Integrate from (x0, v0) (default: :meth:`initial_positions`,
        :meth:`initial_velocities`) for ``n_steps`` (default:
        the Config's) steps; the Dataset of :func:`.results.trajectory_dataset`."""
        from pointatlas.constraints import validate_parameters

        from .integrator import integrate
        from .results import trajectory_dataset

        validate_parameters(self, prefix="physics")
        self.check_config()
        n = self.n_steps if n_steps is None else n_steps
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
            from pointatlas.errors import InputError

            raise InputError(f"n_steps={n!r} is invalid: give a whole number of steps >= 0.")
        body = self.build_body()
        x0 = self.initial_positions(body) if x0 is None else _state(x0, body, "x0", "length")
        v0 = (self.initial_velocities(body) if v0 is None else
              _state(v0, body, "v0", "length / time"))
        mass = body.mass(self.mass)
        traj = integrate(body, mass, x0, v0, float(self.dt), int(n), int(self.save_every),
                         log=getattr(ctx, "log", None))
        return trajectory_dataset(body, traj, self.mass, float(self.dt))


def _plain(value):
    """An OmegaConf DictConfig/ListConfig as a plain dict/list (Hydra hands those over)."""
    if type(value).__module__.startswith("omegaconf"):
        from omegaconf import OmegaConf

        return OmegaConf.to_container(value, resolve=True)
    return value


def _state(given, body, name: str, units: str) -> np.ndarray:
    """``given`` as a finite (n, 2) float array; InputError (one line) otherwise."""
    from pointatlas.errors import InputError

    a = np.asarray(given, dtype=float)
    n = body.mesh.n_nodes
    if a.shape != (n, 2) or not np.all(np.isfinite(a)):
        raise InputError(f"{name} must be a finite array of shape ({n}, 2) ({units}, one row "
                         f"per mesh node), got shape {a.shape}; build it from the mesh of "
                         f"physics.build_body().")
    return a
