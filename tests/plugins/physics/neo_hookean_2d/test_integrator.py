"""Explicit velocity-Verlet: bounded energy error, the stability limit, refusals."""
import numpy as np
import pytest

from pointatlas.errors import InputError
from pointatlas_physics.neo_hookean_2d.body import ElasticBody
from pointatlas_physics.neo_hookean_2d.integrator import critical_time_step, integrate
from pointatlas_physics.neo_hookean_2d.mesh import clamped_nodes, tapered_column
from pointatlas_physics.neo_hookean_2d.statics import static_equilibrium


def _body(n_triangles=160, gravity=(0.0, 0.0)):
    mesh = tapered_column(n_triangles=n_triangles)
    return ElasticBody(mesh, 1000.0, 500.0, 1.0, np.array(gravity),
                       clamped_nodes(mesh.nodes, "bottom"))


def _released(body, push=(3.0, -1.0)):
    """Positions of the static equilibrium under a sideways body force ρ push."""
    return static_equilibrium(body, load=body.nodal_masses[:, None] * np.array(push)).x


def _window_errors(E):
    rel = np.abs(E - E[0]) / abs(E[0])
    k = len(E) // 10
    return rel[1:k + 1].max(), rel[-k:].max()


@pytest.mark.parametrize("kind,steps", [("lumped", 100000), ("consistent", 10000)])
def test_the_energy_of_a_free_vibration_does_not_drift(kind, steps):
    body = _body()
    mass = body.mass(kind)
    x0 = _released(body)
    dt_crit = critical_time_step(body, mass, x0)
    traj = integrate(body, mass, x0, np.zeros_like(x0), 0.4 * dt_crit, steps, 20)
    E = traj.total
    assert E[0] == pytest.approx(body.elastic_energy(x0))          # released from rest, g = 0
    first, last = _window_errors(E)
    assert last < 1e-3 and last < 3 * first + 1e-6, (first, last)
    assert traj.kinetic.max() > 0.5 * E[0]                         # it does swing
    tip = np.argmax(body.reference[:, 1])
    assert traj.x[:, tip, 0].min() < body.reference[tip, 0] < traj.x[:, tip, 0].max()


def test_forward_euler_would_fail_the_energy_check():
    """The check can fail: an explicit Euler step (x += Δt v, v += Δt a) drifts."""
    body = _body(n_triangles=60)
    mass = body.mass("lumped")
    x = _released(body)
    v = np.zeros_like(x)
    dt = 0.2 * critical_time_step(body, mass, x)
    E = []
    for _ in range(3000):
        a = mass.accelerations(body.forces(x))
        x, v = x + dt * v, v + dt * a
        E.append(body.elastic_energy(x) + mass.kinetic_energy(v))
    first, last = _window_errors(np.array(E))
    assert not (last < 1e-3 and last < 3 * first + 1e-6)


def test_the_critical_time_step_matches_the_dense_eigenvalue():
    import scipy.linalg as la

    body = _body(n_triangles=60, gravity=(0.0, -1.0))
    for kind in ("lumped", "consistent"):
        mass = body.mass(kind)
        free = body.free_dofs
        K = body.tangent(body.reference)[free][:, free].toarray()
        M = mass.dof_matrix()[free][:, free].toarray()
        w2 = la.eigh(K, M, eigvals_only=True)[-1]
        assert critical_time_step(body, mass, body.reference) == pytest.approx(
            2 / np.sqrt(w2), rel=1e-5)


def test_a_time_step_above_the_limit_is_refused_in_one_line():
    body = _body(n_triangles=60)
    mass = body.mass("lumped")
    dt_crit = critical_time_step(body, mass, body.reference)
    with pytest.raises(InputError, match=r"physics.dt=.* is above the stability limit .*"
                                         r"Δt_crit = 2/ω_max = .*use physics.dt <=") as err:
        integrate(body, mass, body.reference, np.zeros((body.mesh.n_nodes, 2)),
                  1.05 * dt_crit, 10, 1)
    assert "\n" not in str(err.value)
    # just below the limit the motion stays bounded
    traj = integrate(body, mass, _released(body), np.zeros((body.mesh.n_nodes, 2)),
                     0.95 * dt_crit, 2000, 100)
    assert np.all(np.isfinite(traj.total))


def test_an_inverting_motion_is_refused():
    body = _body(n_triangles=60)
    mass = body.mass("lumped")
    v0 = np.zeros((body.mesh.n_nodes, 2))
    v0[body.free, 1] = -200.0                              # slams the column into its clamp
    with pytest.raises(InputError, match=r"a triangle inverted .* at step \d+"):
        integrate(body, mass, body.reference, v0, 1e-5, 5000, 100)


def test_gravity_alone_makes_the_column_sag_and_bounce():
    body = _body(gravity=(0.0, -1.0))
    mass = body.mass("lumped")
    x0 = body.reference
    traj = integrate(body, mass, x0, np.zeros_like(x0), 2e-5, 2000, 50)
    tip = np.argmax(x0[:, 1])
    assert traj.x[:, tip, 1].min() < x0[tip, 1]
    assert traj.gravity[0] == 0 and traj.gravity.min() < 0
    assert np.allclose(traj.x[:, body.clamped], x0[body.clamped])
