"""At small loads the static neo-Hookean solution is linear elasticity, as scikit-fem's own
plane-strain forms compute it on the same mesh, clamps and body force."""
import numpy as np
import pytest

from pointatlas.errors import InputError
from pointatlas_physics.neo_hookean_2d.body import ElasticBody
from pointatlas_physics.neo_hookean_2d.mesh import clamped_nodes, tapered_column
from pointatlas_physics.neo_hookean_2d.statics import static_equilibrium

LAM, MU, RHO = 1000.0, 500.0, 1.0


def _skfem_displacement(mesh, clamped, gravity, lam, mu, rho):
    """Linear elasticity with ElementVector(ElementTriP1) and linear_elasticity(λ, μ)."""
    skfem = pytest.importorskip("skfem")
    from skfem.models.elasticity import linear_elasticity

    basis = skfem.Basis(mesh.to_skfem(), skfem.ElementVector(skfem.ElementTriP1()))
    K = skfem.asm(linear_elasticity(lam, mu), basis)

    @skfem.LinearForm
    def weight(v, w):
        return rho * (gravity[0] * v[0] + gravity[1] * v[1])

    f = skfem.asm(weight, basis)
    D = basis.nodal_dofs[:, np.flatnonzero(clamped)].ravel()
    u = skfem.solve(*skfem.condense(K, f, D=D))
    return np.column_stack([u[basis.nodal_dofs[0]], u[basis.nodal_dofs[1]]])


def _max_strain(mesh, x):
    from pointatlas_physics.neo_hookean_2d.energy import reference_gradients

    G, _ = reference_gradients(mesh.nodes, mesh.triangles)
    p = x[mesh.triangles]
    F = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]], axis=2) @ G
    return np.abs(0.5 * (np.swapaxes(F, 1, 2) @ F - np.eye(2))).max()


@pytest.mark.parametrize("gravity", [[0.0, -0.15], [0.01, 0.0]],
                         ids=["thesis gravity, scaled", "sideways"])
def test_small_loads_agree_with_skfem_linear_elasticity(gravity):
    mesh = tapered_column(n_triangles=800)
    clamped = clamped_nodes(mesh.nodes, "bottom")
    body = ElasticBody(mesh, LAM, MU, RHO, np.array(gravity), clamped)
    sol = static_equilibrium(body)
    assert sol.residual < 1e-6
    u = sol.x - mesh.nodes
    assert 2e-5 < _max_strain(mesh, sol.x) < 3e-4                  # strains ~ 10⁻⁴
    u_lin = _skfem_displacement(mesh, clamped, gravity, LAM, MU, RHO)
    err = np.linalg.norm(u - u_lin) / np.linalg.norm(u_lin)
    assert err < 1e-3, err
    # the comparison can fail: plane-stress Lamé constants are another material
    lam_stress = 2 * LAM * MU / (LAM + 2 * MU)
    u_other = _skfem_displacement(mesh, clamped, gravity, lam_stress, MU, RHO)
    assert np.linalg.norm(u - u_other) / np.linalg.norm(u_other) > 1e-2


def test_a_large_sideways_load_is_reached_by_load_steps():
    mesh = tapered_column(n_triangles=200)
    body = ElasticBody(mesh, LAM, MU, RHO, np.zeros(2), clamped_nodes(mesh.nodes, "bottom"))
    load = body.nodal_masses[:, None] * np.array([4.0, -1.0])
    sol = static_equilibrium(body, load=load)
    assert sol.residual < 1e-8
    assert (sol.x - mesh.nodes)[:, 0].max() > 0.2                  # a large deflection
    f, jmin = body.internal_forces(sol.x)
    assert jmin > 0 and np.abs((load - f)[body.free]).max() < 1e-7 * np.abs(load).max()


def test_a_load_the_body_cannot_carry_is_one_line():
    mesh = tapered_column(n_triangles=60)
    body = ElasticBody(mesh, LAM, MU, RHO, np.zeros(2), clamped_nodes(mesh.nodes, "bottom"))
    load = body.nodal_masses[:, None] * np.array([0.0, -1e5])   # crushes it flat
    with pytest.raises(InputError, match="no static equilibrium found") as err:
        static_equilibrium(body, load=load, max_iter=8, min_increment=1e-2)
    assert "\n" not in str(err.value)
