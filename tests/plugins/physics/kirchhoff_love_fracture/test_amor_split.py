"""The Amor split through the thickness: intact (g = 1) it is the linear shell energy on a
curved patch; analytic fractions of ψ⁺ in uniaxial compression and in pure bending; the
kernel's gradient and Hessian against finite differences at a degraded point."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pointatlas_kit.assembler import Assembler
from pointatlas_kit.fields import FieldLayout
from pointatlas_physics.kirchhoff_love.linear import linear_stiffness
from pointatlas_physics.kirchhoff_love.shell_energy import ShellEnergy
from pointatlas_physics.kirchhoff_love_fracture.amor_split import AmorSplitShellEnergy
from pointatlas_physics.kirchhoff_love_fracture.degraded_energy import Linearized

E, NU, H = 2.0, 0.3, 0.1
FLAT = np.array([1.0, 0, 0, 0, 1.0, 0] + [0.0] * 9)    # X_,1 = e1, X_,2 = e2, flat


def _point(jet, g=1.0, Y=FLAT, n_z=5):
    energy = AmorSplitShellEnergy(E, NU, H, n_z)
    data = np.concatenate([[g], Y])[None, :]
    dens, grad, hess = energy.evaluate(np.asarray(jet, float)[None, :], data, 2)
    return dens[0], grad[0], hess[0]


def test_intact_split_energy_is_the_linear_shell_energy_on_a_curved_patch(cylinder_patch,
                                                                           material):
    q, _ = cylinder_patch
    amor = AmorSplitShellEnergy(material.young_modulus, material.poisson_ratio,
                                material.thickness)
    layout = FieldLayout(amor.fields, q.n_nodes)
    U = 1e-2 * np.random.default_rng(7).normal(size=layout.n_dofs)
    K = linear_stiffness(q, material)
    A = Assembler(q, layout, [amor])
    dens = A.densities(U)
    assert dens[:, 0].min() > 0 and dens[:, 1].max() > 0      # both parts are present
    total = A.energy(U)["total"]
    assert abs(total - 0.5 * U @ (K @ U)) < 1e-10 * total
    Kt = A.tangent(U)
    # the tangent is that of the piece U lies on; its quadratic form is 2 W there
    assert abs(U @ (Kt @ U) - 2 * total) < 1e-10 * total
    lin = Assembler(q, layout, [Linearized(ShellEnergy(material.young_modulus,
                                                       material.poisson_ratio,
                                                       material.thickness))])
    np.testing.assert_allclose(A.residual(U)[1], lin.residual(U)[1], rtol=0,
                               atol=1e-10 * np.abs(K @ U).max())


def test_uniaxial_compression_drives_with_the_deviatoric_fraction():
    # uniaxial stress σ < 0 along x in plane stress: ε11 = σ/E, ε22 = −ν σ/E
    sigma = -0.01
    jet = np.zeros(15)
    jet[0], jet[4] = sigma / E, -NU * sigma / E
    dens, _, _ = _point(jet)
    W = sigma ** 2 / (2 * E) * H
    assert dens.sum() == pytest.approx(W, rel=1e-12)
    assert dens[0] == pytest.approx((1 + NU) / 2 * W, rel=1e-12)     # ψ⁺ = μ |dev ε|²
    dens_t, _, _ = _point(-jet)                                        # tension: all of W
    assert dens_t[0] == pytest.approx(W, rel=1e-12) and dens_t[1] == 0.0


def test_pure_bending_splits_the_faces():
    # κ11 = κ (u_z,11 = −κ), ε(ζ) = ζ κ e1 ⊗ e1: the face ζ κ > 0 in tension
    kappa = 0.3
    jet = np.zeros(15)
    jet[3 * 2 + 2] = -kappa
    dens, _, _ = _point(jet)
    K2, mu = E / (2 * (1 - NU)), E / (2 * (1 + NU))
    half = H ** 3 / 24 * kappa ** 2        # ∫ ζ² κ² over one half of the thickness
    assert dens[1] == pytest.approx(0.5 * K2 * half, rel=1e-12)
    assert dens[0] == pytest.approx(0.5 * K2 * half + mu * half, rel=1e-12)
    # and the two parts sum to the bending energy ½ h³/12 D11 κ²
    assert dens.sum() == pytest.approx(0.5 * H ** 3 / 12 * E / (1 - NU ** 2) * kappa ** 2,
                                       rel=1e-12)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2 ** 31 - 1), g=st.floats(1e-3, 1.0))
def test_gradient_and_hessian_match_finite_differences(seed, g):
    rng = np.random.default_rng(seed)
    Y = FLAT + 0.3 * rng.normal(size=15)                     # a skew chart, curved
    jet = 1e-2 * rng.normal(size=15)
    dens, grad, hess = _point(jet, g, Y)
    step = 1e-7
    for c in range(15):
        d = np.zeros(15)
        d[c] = step
        dp, gp, _ = _point(jet + d, g, Y)
        dm, gm, _ = _point(jet - d, g, Y)
        scale = np.abs(grad).max() + 1e-30
        # a kink (tr ε = 0 at a thickness point) between the two samples is measure zero
        assert abs((dp.sum() - dm.sum()) / (2 * step) - grad[c]) < 1e-5 * scale
        np.testing.assert_allclose((gp - gm) / (2 * step), hess[:, c], rtol=0,
                                   atol=1e-4 * np.abs(hess).max())
