"""The degraded and linearised shell energies on a curved LME patch (built without the atlas):
the linearised energy is the quadratic form of the shell's linear stiffness, and a
degradation g scales energy, residual and tangent pointwise. (The coupled energy of both
fields is checked against finite differences by the conformance suite.)"""
import numpy as np

from pointatlas_kit.assembler import Assembler
from pointatlas_kit.fields import FieldLayout
from pointatlas_physics.kirchhoff_love.linear import linear_stiffness
from pointatlas_physics.kirchhoff_love.shell_energy import ShellEnergy
from pointatlas_physics.kirchhoff_love_fracture.degraded_energy import (DegradedEnergy,
                                                                        Linearized)


def test_linearised_energy_is_half_u_k_u_and_degradation_scales_it(cylinder_patch, material):
    q, P = cylinder_patch
    shell = ShellEnergy(material.young_modulus, material.poisson_ratio, material.thickness)
    layout = FieldLayout(shell.fields, q.n_nodes)
    rng = np.random.default_rng(4)
    U = 1e-2 * rng.normal(size=layout.n_dofs)
    K = linear_stiffness(q, material)
    lin = Assembler(q, layout, [Linearized(shell)])
    E = lin.energy(U)["total"]
    assert abs(E - 0.5 * U @ (K @ U)) < 1e-10 * abs(E)
    np.testing.assert_allclose(lin.residual(U)[1], K @ U, rtol=0, atol=1e-10 * np.abs(K @ U).max())
    g = rng.uniform(0.01, 1.0, q.n_points)
    deg = DegradedEnergy(Linearized(shell), g)
    A = Assembler(q, layout, [deg])
    dens = A.densities(U)[:, 0]
    np.testing.assert_allclose(dens, g * lin.densities(U)[:, 0], rtol=1e-12, atol=1e-300)
    deg.degradation = np.full(q.n_points, 0.25)
    A.refresh_data()
    Kd = A.tangent(np.zeros(layout.n_dofs))
    np.testing.assert_allclose(Kd.toarray(), 0.25 * K.toarray(), rtol=0,
                               atol=1e-12 * np.abs(K).max())
