"""Plugin conformance suite: run it on your plugin (our tests run it on every built-in one).

>>> from pointatlas.testing import check_plugin
>>> check_plugin("embedders", MyEmbedder)          # doctest: +SKIP

Each ``check_*`` raises ``AssertionError`` naming the broken rule.
"""
from __future__ import annotations

import copy
import dataclasses
import inspect
from typing import Any

import numpy as np

from .registry import FAMILIES, group_name


def check_contract(cls: type) -> None:
    """Rules every plugin follows: a Config dataclass mirrored by a keyword-only ``__init__``
    that only stores, and a one-line description."""
    name = cls.__name__
    config = getattr(cls, "Config", None)
    assert config is not None and dataclasses.is_dataclass(config), (
        f"{name} must define a class attribute `Config` that is a @dataclass")
    desc = getattr(cls, "description", None)
    assert isinstance(desc, str) and desc.strip() and "\n" not in desc.strip(), (
        f"{name}.description must be a one-line string")
    params = inspect.signature(cls.__init__).parameters
    fields = {f.name for f in dataclasses.fields(config)}
    positional = [p for p, v in params.items() if p != "self" and v.kind in (
        v.POSITIONAL_ONLY, v.POSITIONAL_OR_KEYWORD)]
    assert not positional, f"{name}.__init__ must be keyword-only (found positional {positional})"
    named = {p for p, v in params.items() if v.kind == v.KEYWORD_ONLY}
    assert named == fields, (
        f"{name}.__init__ keywords {sorted(named)} differ from its Config fields {sorted(fields)}")
    try:
        defaults = dataclasses.asdict(config())
    except TypeError:
        return  # a Config with required fields: nothing more to check without values
    obj = cls(**defaults)
    for key, value in defaults.items():
        assert hasattr(obj, key) and _same(getattr(obj, key), value), (
            f"{name}.__init__ must store {key!r} unchanged (scikit-learn convention)")
    _check_hydra(config, name)
    check_parameter_constraints(cls, defaults)
    check_refuses_bad_values(cls, defaults)


def check_parameter_constraints(cls: type, defaults: dict | None = None) -> None:
    """The ``parameter_constraints`` of ``cls.Config`` are well formed (lists of
    :mod:`pointatlas.constraints` objects, keyed by Config fields) and its defaults meet them."""
    from .constraints import declared_constraints, describe, meets
    from .errors import PluginError

    name = cls.__name__
    try:
        declared = declared_constraints(cls)
    except PluginError as exc:
        raise AssertionError(str(exc)) from exc
    for key, allowed in declared.items():
        if defaults is not None and key in defaults:
            assert meets(defaults[key], allowed), (
                f"{name}.Config default {key}={defaults[key]!r} does not meet its own declared "
                f"constraint ({describe(allowed)})")


def check_refuses_bad_values(cls: type, defaults: dict) -> None:
    """A bad value is refused with :class:`pointatlas.ConfigError` or ``ValueError``.

    For each float setting, the plugin is built with NaN there and given the start-up check
    (:func:`pointatlas.config_check.check_plugin_settings`: its declared parameter
    constraints, then its ``check_config()``); they may raise only ``ValueError``
    (ConfigError is one), and a plugin that declares a constraint on that setting or has a
    ``check_config`` must refuse the NaN: no parameter of a plugin is meaningful as NaN.
    """
    from .config_check import check_plugin_settings
    from .constraints import declared_constraints

    name = cls.__name__
    declared = declared_constraints(cls)
    for key, value in defaults.items():
        if isinstance(value, bool) or not isinstance(value, float):
            continue
        try:
            check_plugin_settings(cls(**{**defaults, key: float("nan")}))
        except ValueError:
            continue
        except Exception as exc:  # noqa: BLE001 - the wrong kind of refusal is the failure
            raise AssertionError(
                f"{name} with {key}=nan raised {type(exc).__name__} ({exc}); refuse bad values "
                "with pointatlas.ConfigError (or ValueError) naming the key and the fix") from exc
        assert key not in declared, (
            f"{name} accepts {key}=nan although its Config declares a constraint on {key}")
        assert not callable(getattr(cls, "check_config", None)), (
            f"{name}.check_config() accepts {key}=nan; declare {key}'s valid range in "
            "Config.parameter_constraints (pointatlas.constraints.Interval) or check it, and "
            "raise pointatlas.ConfigError naming it and the fix")


def _same(a, b) -> bool:
    try:
        return bool(a == b) if not isinstance(a, float) or a == a else b != b
    except Exception:  # noqa: BLE001
        return a is b


def _check_hydra(config: type, name: str) -> None:
    from omegaconf import OmegaConf

    try:
        OmegaConf.structured(config)
    except Exception as exc:  # noqa: BLE001
        raise AssertionError(f"{name}.Config is not a valid Hydra structured config: {exc}") from exc


def _swiss_roll(n: int = 400, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = 1.5 * np.pi * (1 + 2 * rng.random(n))
    h = 10 * rng.random(n)
    return np.column_stack([t * np.cos(t), h, t * np.sin(t)])


def check_source(cls: type, **kwargs: Any) -> None:
    from .pointcloud import PointCloud

    check_contract(cls)
    a = cls(**kwargs).load(np.random.default_rng(1))
    b = cls(**kwargs).load(np.random.default_rng(1))
    if hasattr(a, "frames") and hasattr(a, "times"):       # a frame source (images + times)
        assert np.isfinite(a.frames).all() and np.isfinite(a.times).all(), (
            f"{cls.__name__}.load returned non-finite frames or times")
        np.testing.assert_array_equal(a.frames, b.frames, err_msg=(
            f"{cls.__name__}: the same rng seed must give the same frames"))
        return
    assert isinstance(a, PointCloud), f"{cls.__name__}.load must return a PointCloud"
    assert np.isfinite(a.points).all(), f"{cls.__name__}.load returned non-finite points"
    np.testing.assert_array_equal(a.points, b.points, err_msg=(
        f"{cls.__name__}: the same rng seed must give the same points"))


def check_embedder(cls: type, *, transform_rtol: float = 1e-8, **kwargs: Any) -> None:
    """The plugin contract, ``fit`` / ``embedding_`` / ``fit_transform`` on a 400-point swiss
    roll, NaN refused; and, for an embedder with ``transform`` (out-of-sample embedding), after
    ``fit(X)``:

    - ``transform(X[:k])`` of training points has shape (k, n_components), is finite and gives
      back ``embedding_[:k]`` to within ``transform_rtol`` times the embedding's spread (RMS
      distance of ``embedding_`` to its centroid). The default asks for an exact reproduction;
      an extension that only approximates training points by design (LLE's barycentric map
      reproduces y_i up to the LLE residual) passes the bound it guarantees;
    - new points near training points (moved 5% of their nearest-neighbour distance) land within
      a tenth of the spread of those points' embeddings: ``transform`` is an extension of the
      embedding, not a look-up of the training points;
    - ``transform`` of a point with a NaN coordinate raises ``ValueError``.

    An embedder without ``transform`` (allowed: ``fit`` / ``embedding_`` is the protocol) skips
    these. ``kwargs``: Config values to use.
    """
    check_contract(cls)
    name = cls.__name__
    X = _swiss_roll()
    est = cls(**kwargs)
    assert est.fit(X) is est, f"{name}.fit must return self"
    Y = np.asarray(est.embedding_)
    d = getattr(est, "n_components", 2)
    assert Y.shape == (len(X), d), f"{name}.embedding_ has shape {Y.shape}, not {(len(X), d)}"
    assert np.isfinite(Y).all(), f"{name} produced non-finite embedding values"
    Z = np.asarray(cls(**kwargs).fit_transform(X))
    assert Z.shape == Y.shape, f"{name}.fit_transform must return (n, n_components)"
    bad = X.copy()
    bad[3, 1] = np.nan
    try:
        cls(**kwargs).fit(bad)
    except (ValueError, ArithmeticError):
        pass
    else:
        raise AssertionError(f"{name}.fit accepted NaN coordinates; it must raise")
    if callable(getattr(est, "transform", None)):
        _check_transform(est, X, Y, transform_rtol)


def _check_transform(est, X: np.ndarray, Y: np.ndarray, rtol: float, k: int = 20,
                     near_rtol: float = 0.1) -> None:
    """``check_embedder``'s rules for ``transform`` of a fitted ``est`` (``X`` its training
    points, ``Y`` their ``embedding_``)."""
    from scipy.spatial import cKDTree

    name = type(est).__name__
    spread = float(np.sqrt(np.mean(np.sum((Y - Y.mean(axis=0)) ** 2, axis=1))))
    T = np.asarray(est.transform(X[:k]))
    assert T.shape == (k, Y.shape[1]), (
        f"{name}.transform of {k} points has shape {T.shape}, not {(k, Y.shape[1])}")
    assert np.isfinite(T).all(), f"{name}.transform of training points gave non-finite values"
    worst = float(np.linalg.norm(T - Y[:k], axis=1).max())
    assert worst <= rtol * spread, (
        f"{name}.transform of training points is {worst / spread:.3g} x the embedding's spread "
        f"away from their embedding_ (allowed {rtol:g}); pass transform_rtol= to check_embedder "
        "only if your out-of-sample map reproduces training points approximately by design")
    rng = np.random.default_rng(1)
    step = cKDTree(X).query(X[:k], k=2)[0][:, 1]
    u = rng.standard_normal(X[:k].shape)
    near = X[:k] + 0.05 * step[:, None] * u / np.linalg.norm(u, axis=1, keepdims=True)
    far = float(np.linalg.norm(np.asarray(est.transform(near)) - Y[:k], axis=1).max())
    assert far <= near_rtol * spread, (
        f"{name}.transform puts points 5% of a neighbour spacing from training points "
        f"{far / spread:.3g} x the embedding's spread away from their embedding_ "
        f"(allowed {near_rtol:g}): new points must be placed near the training points they are near")
    bad = X[:k].copy()
    bad[3, 1] = np.nan
    try:
        est.transform(bad)
    except ValueError:
        return
    except Exception as exc:  # noqa: BLE001 - the wrong kind of refusal is the failure
        raise AssertionError(f"{name}.transform of a NaN coordinate raised {type(exc).__name__} "
                             f"({exc}); it must raise ValueError") from exc
    raise AssertionError(f"{name}.transform accepted NaN coordinates; it must raise ValueError")


def check_approximant(cls: type, *, dim: int = 2, reproduces_linear: bool = False, **kwargs: Any) -> None:
    """Partition of unity, gradients summing to 0, non-negative values unless the class says
    ``non_negative = False`` (moving least squares), and linear reproduction when claimed,
    at interior points."""
    check_contract(cls)
    rng = np.random.default_rng(0)
    nodes = rng.random((150, dim))
    points = 0.3 + 0.4 * rng.random((40, dim))
    basis = cls(**kwargs).fit(nodes).evaluate(points, order=1)
    assert basis.indptr.shape == (len(points) + 1,), "indptr must have m+1 entries"
    rows = np.repeat(np.arange(len(points)), np.diff(basis.indptr))
    total = np.bincount(rows, weights=basis.values, minlength=len(points))
    np.testing.assert_allclose(total, 1.0, atol=1e-8, err_msg="basis functions must sum to 1")
    if getattr(cls, "non_negative", True):
        assert (basis.values >= -1e-14).all(), ("basis function values must be non-negative "
                                                "(or the class declares non_negative = False)")
    assert basis.gradients is not None and basis.gradients.shape == (len(basis.values), dim)
    gsum = np.zeros((len(points), dim))
    np.add.at(gsum, rows, basis.gradients)
    np.testing.assert_allclose(gsum, 0.0, atol=1e-7, err_msg="gradients must sum to 0")
    if reproduces_linear:
        rec = np.zeros((len(points), dim))
        np.add.at(rec, rows, basis.values[:, None] * nodes[basis.indices])
        np.testing.assert_allclose(rec, points, atol=1e-8, err_msg="linear reproduction fails")


def check_physics(cls: type, *, solve_case: dict | None = None, **kwargs: Any) -> None:
    """The plugin contract, ``solve``, declared ``fields`` and, for a physics written on the
    kit (``discrete_energy``), its residual and tangent against finite differences of its
    energy on a small curved patch, a symmetric tangent and rigid-motion invariance where
    claimed (:mod:`pointatlas.physics_conformance`). ``kwargs``: Config values to use.

    With ``solve_case`` (Config values of a small solvable problem on an open curved patch;
    default: the class attribute ``conformance_case``, if any) the physics built from them
    (merged with ``kwargs``) is solved on that patch and the Dataset ``solve`` returns is
    checked: named dims, ``long_name``/``units`` on every variable, the declared fields over
    the ``point`` coordinate, finite values (:mod:`pointatlas.physics_dataset_check`).
    """
    check_contract(cls)
    name = cls.__name__
    assert callable(getattr(cls, "solve", None)), f"{name} must define solve(ctx, ...)"
    fields = getattr(cls, "fields", ())
    if callable(getattr(cls, "discrete_energy", None)):
        assert fields and all(hasattr(f, "name") and hasattr(f, "components") and
                              hasattr(f, "order") for f in fields), (
            f"{name}.fields must declare the fields of its energies (kit Field objects)")
        from .physics_conformance import check_discrete_energy

        check_discrete_energy(cls(**kwargs))
    case = getattr(cls, "conformance_case", None) if solve_case is None else solve_case
    if case is not None:
        _check_solve_case(cls, case, fields, kwargs)


def _check_solve_case(cls: type, case: Any, fields, kwargs: dict) -> None:
    """Solve ``case`` on the conformance patch; check the Dataset and the fields it holds."""
    from .config_check import check_plugin_settings
    from .physics_dataset_check import check_physics_dataset, solve_conformance_case

    name = cls.__name__
    assert isinstance(case, dict), (
        f"{name}.conformance_case must be a dict of Config values, got {type(case).__name__}")
    config_keys = {f.name for f in dataclasses.fields(cls.Config)}
    unknown = sorted(set(case) - config_keys)
    assert not unknown, (
        f"{name}.conformance_case has key(s) {unknown} that are not Config fields "
        f"({sorted(config_keys)})")
    assert all(hasattr(f, a) for f in fields for a in ("name", "components", "units",
                                                       "long_name")), (
        f"{name}.fields must be kit Field objects (name, components, units, long_name)")
    try:
        check_plugin_settings(cls(**copy.deepcopy({**case, **kwargs})))
    except ValueError as exc:  # ConfigError is one
        raise AssertionError(f"{name}.conformance_case fails the start-up checks: {exc}") from exc
    _, cloud, ds = solve_conformance_case(cls, case, **kwargs)
    check_physics_dataset(ds, fields, name, n_points=cloud.n_points)


def check_study(cls: type, **kwargs: Any) -> None:
    check_contract(cls)
    assert callable(getattr(cls, "run", None)), f"{cls.__name__} must define run(ctx)"


def check_atlas(cls: type, **kwargs: Any) -> None:
    check_contract(cls)
    assert callable(getattr(cls, "settings", None)), (
        f"{cls.__name__} must define settings() returning the atlas settings")


def conformance_task(shared, item):
    """A pure task for :func:`check_executor`: shared + item, or a failure at item 2."""
    if item == 2:
        raise ArithmeticError("the conformance task fails at item 2 on purpose")
    return shared + item


def check_executor(cls: type, **kwargs: Any) -> None:
    """An executor maps a pure function in the order of the items, sends ``shared`` with
    them, names the failing item in one TaskError, and closes. An executor whose workers are
    batch jobs (it has ``job_script``) is checked by its job script instead of by running."""
    from .executor import TaskError

    check_contract(cls)
    name = cls.__name__
    ex = cls(**kwargs)
    assert isinstance(getattr(ex, "distributed", None), bool), (
        f"{name}.distributed must be a bool (whether the tasks run in other processes)")
    if callable(getattr(ex, "job_script", None)):
        script = ex.job_script()
        assert isinstance(script, str) and script.startswith("#!"), (
            f"{name}.job_script() must return the batch script (starting with #!)")
        return
    try:
        out = ex.map(conformance_task, [5, 1, 7, 3], shared=10, desc="conformance",
                     labels=["patch 0", "patch 1", "patch 2", "patch 3"])
        assert list(out) == [15, 11, 17, 13], (
            f"{name}.map must return fn(shared, item) in the order of the items; got {out}")
        try:
            ex.map(conformance_task, [0, 1, 2, 3], shared=0, desc="conformance",
                   labels=["patch 0", "patch 1", "patch 2", "patch 3"])
        except TaskError as exc:
            assert "patch 2" in str(exc) and "\n" not in str(exc).strip(), (
                f"{name}.map's error must name the failing item in one line; got {exc}")
        else:
            raise AssertionError(f"{name}.map ignored a task that raised")
    finally:
        ex.close()


CHECKS = {
    "source": check_source,
    "embedder": check_embedder,
    "approximant": check_approximant,
    "physics": check_physics,
    "study": check_study,
    "atlas": check_atlas,
    "executor": check_executor,
}


def check_plugin(family: str, cls: type, **kwargs: Any) -> None:
    """Run the conformance checks of ``family`` ('embedders', 'embedder', ...) on ``cls``."""
    CHECKS[FAMILIES[group_name(family)]](cls, **kwargs)


def composed_context(run_dir, overrides=()):
    """A :class:`~pointatlas.context.RunContext` for config ``overrides`` composed as the CLI
    composes them (Hydra, the registered configs and experiments), running in ``run_dir``
    (created): for tests that run a study in-process, e.g. to interrupt and resume it."""
    from pathlib import Path

    from hydra import compose, initialize_config_dir
    from omegaconf import OmegaConf, open_dict

    from .config import CONF_DIR, register_configs
    from .context import RunContext
    from .registry import FAMILIES

    register_configs()
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        cfg = compose("config", overrides=list(overrides), return_hydra_config=True)
    families = set(FAMILIES.values())
    choices = {k: v for k, v in cfg.hydra.runtime.choices.items() if k in families and v}
    with open_dict(cfg):
        del cfg["hydra"]
    config = OmegaConf.to_container(cfg, resolve=True)
    Path(run_dir).mkdir(parents=True, exist_ok=True)
    return RunContext(config=config, choices=choices, seed=int(config["seed"]),
                      run_dir=Path(run_dir))
