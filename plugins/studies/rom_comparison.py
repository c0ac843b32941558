"""The comparison of :mod:`.rom_neo_hookean`: training set, intrinsic dimension, slow manifolds
of every method and dimension, reduced runs from the held-out starts, D and e (Eqs. 12–13), and
the arrays its figures draw (embeddings, reduced mass and effective potential, snapshot strips).
"""
from __future__ import annotations

import numpy as np

from pointatlas.errors import ConfigError, InputError


def _v(ds, name, dims, value, long_name, units="1"):
    ds[name] = (dims, np.asarray(value), {"long_name": long_name, "units": units})


def _windows(st, snap):
    n_traj, n_time, _ = snap.position.shape
    n_drop = snap.start
    dt_snap = float(snap.time[1] - snap.time[0])
    n_window = int(round(st.test_duration / dt_snap))
    if n_window < 1 or n_drop + n_window >= n_time:
        raise ConfigError(
            f"study.test_duration={st.test_duration:g} needs {n_window} snapshots after the "
            f"{n_drop} dropped, but the trajectories hold {n_time}; shorten test_duration or "
            f"run longer trajectories (physics.n_steps).")
    sub = int(round(dt_snap / st.dt))
    if sub < 1 or abs(sub * st.dt - dt_snap) > 1e-6 * dt_snap:
        raise ConfigError(f"study.dt={st.dt:g} does not divide the snapshot interval "
                          f"{dt_snap:g}; choose dt = {dt_snap:g}/k.")
    return n_drop, n_window, sub


def _training(st, snap, n_drop):
    from pointatlas_reduction.training_set import boundary_nodes, decimate, landmark_columns
    from pointatlas_studies.rom_training import rms_radius

    n_train = snap.n_trajectories - st.n_test
    D = snap.position.shape[2]
    X = snap.position[:n_train, n_drop:].reshape(-1, D)
    nodes = boundary_nodes(snap.triangles, exclude=np.flatnonzero(snap.clamped))
    cols = landmark_columns(nodes)
    rms = rms_radius(X[:, cols])
    keep = decimate(X[:, cols], st.decimation * rms)
    return X, keep, cols, rms


def _check_starts(st, snap, test, n_drop, Xl, cols, rms):
    from scipy.spatial import cKDTree

    dist, _ = cKDTree(Xl).query(snap.position[test, n_drop][:, cols])
    for i, d in zip(test, dist):
        if d > st.max_start_distance * rms:
            raise InputError(
                f"test trajectory {i} starts {d:.4g} from the nearest training snapshot "
                f"({d / rms:.3g} × the training set's rms radius {rms:.4g}, above "
                f"study.max_start_distance={st.max_start_distance:g}): the slow manifold is "
                f"not sampled there, so the reduced model is refused. Train on trajectories "
                f"that visit that region (more of them), or raise max_start_distance.")
    return dist


def compare(ctx, st, body, snap):
    import xarray as xr

    from pointatlas_embedders.intrinsic_dimension import (correlation_dimension,
                                                          local_pca_residual_variance)
    from pointatlas_reduction.affine_manifold import AffineManifold
    from pointatlas_reduction.reduced_lagrangian import ReducedLagrangian
    from pointatlas_studies.rom_models import (nonlinear_manifold, pca_manifold,
                                               pca_reconstruction_error, reconstruction_error,
                                               reduced_run, trajectory_distance)

    n_drop, n_window, sub = _windows(st, snap)
    test = np.arange(snap.n_trajectories - st.n_test, snap.n_trajectories)
    with ctx.timed("training_set"):
        X, keep, cols, rms = _training(st, snap, n_drop)
    Xd, Xl = X[keep], X[keep][:, cols]
    ctx.log.info("training set: %d snapshots, %d after decimation, %d landmark coordinates",
                 len(X), len(keep), len(cols))
    start_dist = _check_starts(st, snap, test, n_drop, Xl, cols, rms)
    mass = np.repeat(snap.nodal_mass, 2)
    mass[np.repeat(snap.clamped, 2)] = 0.0

    def potential(x):
        y = x.reshape(-1, 2)
        return body.potential_energy(y), -body.forces(y).ravel()

    full = snap.position[test, n_drop:n_drop + n_window + 1]          # (n_test, n_win+1, D)
    rng = ctx.rng("error_samples")
    pool = snap.position[test, n_drop:].reshape(-1, X.shape[1])
    Z = pool[np.sort(rng.choice(len(pool), min(st.n_error_samples, len(pool)), False))]
    with ctx.timed("intrinsic_dimension"):
        S = Xl[np.sort(rng.choice(len(Xl), min(3000, len(Xl)), False))]
        scales, C, dcorr = correlation_dimension(S)
        dims, lpca, _ = local_pca_residual_variance(S, n_window=20)
    methods = ["pca"] + [str(m) for m in st.nonlinear]
    ncomp = sorted({int(d) for d in list(st.pca_dims) + list(st.nonlinear_dims)})
    shape = (len(test), len(methods), len(ncomp))
    Dist, reached, wall = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    e = np.full(shape[1:], np.nan)
    n_nodes, resid = np.full(shape[1:], np.nan), np.full(shape[1:], np.nan)
    warnings, strips, embeddings, maps = [], {}, {}, None
    frames = np.linspace(0, n_window, st.n_frames).round().astype(int)

    def run_all(manifold, mi, di, label, strip):
        RL = ReducedLagrangian(manifold, mass, potential)
        for k, i in enumerate(test):
            x0 = snap.position[i, n_drop]
            v0 = snap.velocity[i]
            r = reduced_run(manifold, RL, x0, v0, mass, st.dt, n_window * sub, sub)
            reached[k, mi, di], wall[k, mi, di] = r.reached, r.wall
            if r.failure:
                warnings.append(f"{label}, test trajectory {i}: stopped at t = "
                                f"{r.reached:.4g} of {n_window * sub * st.dt:.4g} "
                                f"({r.failure.split(';')[0]})")
            else:
                Dist[k, mi, di] = trajectory_distance(full[k], r.X, mass)
            if k == 0 and strip:
                s = np.full((len(frames), X.shape[1]), np.nan)
                ok = frames < len(r.X)
                s[ok] = r.X[frames[ok]]
                strips[label] = s
        ctx.log.info("%s: D = %s, e = %.3e", label,
                     np.array2string(Dist[:, mi, di], precision=3), e[mi, di])

    with ctx.timed("pca"):
        mean, comps = pca_manifold(X, max(st.pca_dims), stride=max(1, len(X) // 20000))
        e_pca = pca_reconstruction_error(mean, comps, Z)
        for d in sorted(int(d) for d in st.pca_dims):
            di = ncomp.index(d)
            e[0, di] = e_pca[d - 1]
            run_all(AffineManifold(mean, comps[:d]), 0, di, f"pca d={d}",
                    d == st.strip_pca_dim)
    for mi, name in enumerate(methods[1:], start=1):
        for d in sorted(int(d) for d in st.nonlinear_dims):
            di = ncomp.index(d)
            with ctx.timed(f"{name}_embedding"):
                sm, Q = nonlinear_manifold(ctx, name, d, Xd, Xl, st)
            n_nodes[mi, di], resid[mi, di] = len(sm.nodes_), sm.residual_
            with ctx.timed(f"{name}_reduced"):
                e[mi, di] = reconstruction_error(sm, Z)
                run_all(sm, mi, di, f"{name} d={d}", True)
            if d == 2:
                embeddings[name] = Q
                if maps is None:
                    maps = _maps(sm, ReducedLagrangian(sm, mass, potential), Q, st.n_map)
    ds = xr.Dataset(coords={
        "method": ("method", methods, {"long_name": "reduction method", "units": "1"}),
        "n_components": ("n_components", ncomp, {"long_name": "reduced dimension d",
                                                  "units": "1"}),
        "test": ("test", test, {"long_name": "held-out trajectory index", "units": "1"})})
    md = ("method", "n_components")
    _v(ds, "trajectory_distance", md, Dist.mean(axis=0), "trajectory distance D (Eq. 13), "
       "mean over the held-out trajectories (NaN: not computed, or a reduced run stopped "
       "early)")
    _v(ds, "trajectory_distance_per_test", ("test",) + md, Dist,
       "trajectory distance D (Eq. 13) of each held-out trajectory")
    _v(ds, "reconstruction_error", md, e, "relative reconstruction error e (Eq. 12) on "
       "held-out snapshots")
    _v(ds, "reduced_time_reached", ("test",) + md, reached,
       "time the reduced run reached (test_duration unless it stopped)", "s")
    _v(ds, "reduced_wall_per_time", md, np.nanmean(wall / reached, axis=0),
       "wall time of the reduced model per simulated time unit (direct LME evaluation)", "s")
    _v(ds, "lme_nodes", md, n_nodes, "LME nodes of the slow manifold")
    _v(ds, "fit_residual", md, resid, "rms distance of the training snapshots to X(q)")
    _v(ds, "start_distance", ("test",), start_dist, "distance of each test start to the "
       "nearest training snapshot (landmarks)")
    _scalars(ds, X, keep, cols, rms, snap, n_window, sub, st)
    _v(ds, "correlation_scale", ("scale",), scales, "radius ε of the correlation dimension")
    _v(ds, "correlation_dimension", ("scale",), dcorr, "d log C / d log ε")
    lp = min(20, len(dims))
    _v(ds, "local_pca_residual", ("local_dim",), lpca[:lp], "mean 1 − Σ_{i≤d} λ_i / Σ λ_i "
       "over local windows of 20 snapshots")
    ds = ds.assign_coords(local_dim=("local_dim", dims[:lp], {"long_name": "d", "units": "1"}))
    _figure_arrays(ds, X, keep, cols, embeddings, maps, strips, full[0], frames, snap, st)
    if warnings:
        ds.attrs["warnings"] = "; ".join(warnings)
    return ds


def _scalars(ds, X, keep, cols, rms, snap, n_window, sub, st):
    for name, val, long in (
            ("n_snapshots", len(X), "training snapshots before decimation"),
            ("n_training", len(keep), "training snapshots after decimation"),
            ("n_landmark_coordinates", len(cols), "landmark coordinates (D of the embedding)"),
            ("n_full_coordinates", X.shape[1], "coordinates of a full configuration"),
            ("n_steps_reduced", n_window * sub, "reduced steps per test run"),
            ("rms_radius", rms, "rms radius of the landmark training set")):
        _v(ds, name, (), val, long)
    _v(ds, "test_window", (), n_window * sub * st.dt, "simulated time of each test run", "s")


def _maps(sm, RL, Q, n):
    """Reduced mass trace and effective potential on an n × n grid over the 2-D embedding."""
    g1 = np.linspace(Q[:, 0].min(), Q[:, 0].max(), n)
    g2 = np.linspace(Q[:, 1].min(), Q[:, 1].max(), n)
    tr, V = np.full((n, n), np.nan), np.full((n, n), np.nan)
    for j, b in enumerate(g2):
        for i, a in enumerate(g1):
            q = np.array([a, b])
            if sm.contains(q):
                T = RL.terms(q)
                tr[j, i], V[j, i] = np.trace(T.mass), T.potential
    return g1, g2, tr, V


def _figure_arrays(ds, X, keep, cols, embeddings, maps, strips, full0, frames, snap, st):
    first = X[0, cols]
    n = min(3000, len(keep))
    pick = np.linspace(0, len(keep) - 1, n).round().astype(int)
    dist = np.linalg.norm(X[keep[pick]][:, cols] - first, axis=1)
    _v(ds, "embedding_distance", ("sample",), dist, "distance of each plotted training "
       "snapshot to the first configuration (landmarks)")
    for name, Q in embeddings.items():
        _v(ds, f"embedding_{name}", ("sample", "coordinate"), Q[pick],
           f"two-dimensional {name} embedding of the training set (sampled)")
    if maps is not None:
        g1, g2, tr, V = maps
        ds.coords["map_q1"] = ("map_q1", g1, {"long_name": "q₁", "units": "1"})
        ds.coords["map_q2"] = ("map_q2", g2, {"long_name": "q₂", "units": "1"})
        _v(ds, "reduced_mass_trace", ("map_q2", "map_q1"), tr, "trace of the reduced mass "
           "M̃(q) of the first nonlinear method, d = 2 (NaN outside the sampled region)")
        _v(ds, "effective_potential", ("map_q2", "map_q1"), V, "effective potential Ṽ(q) "
           "of the first nonlinear method, d = 2")
    labels = ["full"] + list(strips)
    arr = np.stack([full0[frames]] + [strips[k] for k in strips])
    ds.coords["strip_model"] = ("strip_model", labels, {"long_name": "model", "units": "1"})
    ds.coords["frame_time"] = ("frame", frames * float(snap.time[1] - snap.time[0]),
                               {"long_name": "time since the test start", "units": "s"})
    _v(ds, "strip_position", ("strip_model", "frame", "node", "dim"),
       arr.reshape(len(labels), len(frames), -1, 2), "node positions of the first test "
       "trajectory, full and reduced", "m")
    _v(ds, "face_node_connectivity", ("face", "corner"), snap.triangles, "mesh triangles")
