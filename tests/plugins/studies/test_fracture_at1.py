"""study=fracture with ``physics.crack_model=at1`` against its closed form: the quarter plate
of test_fracture_nonlinear (pulled along y, free lateral contraction, homogeneous uniaxial
stress, linear kinematics: ψ = ½ E h ε², ε = 2 PULL t) has AT1's elastic phase, υ = 1
exactly while ψ ≤ ψ_c = 3 G_c h/(32κ̄), with the undamaged reaction ½ h (1 + η) E ε (AT2 has
none: its υ = c/(c + 2ψ) < 1 at any strain). Past ψ_c the homogeneous AT1 state υ = ψ_c/ψ
softens (σ ∝ ε⁻³), which under displacement control on a plate ten bands wide is unstable:
a crack localises at once. Measured: the path (0.175, 0.35, halved twice at the jump) is
intact at t = 0.175 and 0.2625 (ψ/ψ_c = 0.33, 0.735) and cracked through (min υ 0.014) at
0.30625, where ψ/ψ_c = 1.0004.
"""
import numpy as np
import pytest

from pointatlas.testing import composed_context

E, H, GC, KAPPA, ETA = 1.0, 0.1, 1e-3, 0.05, 1e-6
PULL = 0.1
PSI_C = 3 * GC * H / (32 * KAPPA)
CASE = ["experiment=fracture_griffith", "source.n_points=441", f"physics.length_scale={KAPPA}",
        "physics.precracks=[]", "study.griffith_half_length=null", "atlas.quadrature_order=5",
        "study.n_increments=2", "study.max_factor=0.35", "physics.staggered_tol=1e-9",
        f"physics.young_modulus={E}", f"physics.thickness={H}", "physics.kinematics=linear",
        f"physics.fracture_toughness={GC}", f"physics.residual_stiffness={ETA}",
        "physics.supports=[{kind: symmetry, normal: [1, 0, 0], where: {plane: [1, 0, 0, 0]}},"
        " {kind: symmetry, normal: [0, 1, 0], where: {plane: [0, 1, 0, 0]}},"
        " {kind: displacement, components: [1, 2], value: [0, 0.1, 0],"
        " where: {plane: [0, 1, 0, 0.5]}}]"]


def _run(run_dir, *overrides):
    ctx = composed_context(run_dir, [*CASE, *overrides])
    return ctx.plugin("study").run(ctx)


def _closed_form(t):
    eps = 2.0 * PULL * np.asarray(t)
    psi = 0.5 * E * H * eps ** 2
    v = np.minimum(1.0, PSI_C / psi)
    return v, 0.5 * H * (v * v + ETA) * E * eps, psi / PSI_C


@pytest.fixture(scope="module")
def at1(tmp_path_factory):
    return _run(tmp_path_factory.mktemp("at1") / "run", "physics.crack_model=at1")


def test_at1_is_intact_below_its_threshold_and_cracks_past_it(at1):
    t = at1["load_factor"].values
    v_exact, r_exact, ratio = _closed_form(t[1:])
    v = at1["phase_field"].values[1:]
    below, above = ratio < 1, ratio > 1
    assert below.sum() >= 2 and above.sum() >= 1
    # the elastic phase: intact, every nodal value at its bound 1 (Σ p_b = 1 to round-off)
    np.testing.assert_allclose(v[below], 1.0, rtol=0, atol=1e-14)
    np.testing.assert_allclose(at1["reaction"].values[1:][below], r_exact[below], rtol=5e-4)
    assert np.all(v[above].min(axis=1) < 0.1)         # localised: a crack, not υ = ψ_c/ψ
    assert np.all(np.diff(at1["phase_field"].values, axis=0) <= 0.0)


def test_at2_on_the_same_path_has_no_elastic_phase(tmp_path):
    """AT2's first increment of the same path (t = 0.175, ψ/ψ_c = 0.33): damaged already. Only
    that increment is run (the whole path to 0.35 cracks AT2 too and took 6 min here)."""
    at2 = _run(tmp_path / "at2", "study.n_increments=1", "study.max_factor=0.175")
    v = at2["phase_field"].values
    c = GC * H / (2 * KAPPA)
    psi = _closed_form(at2["load_factor"].values[1])[2] * PSI_C
    np.testing.assert_allclose(v[1], c / (c + 2 * psi), atol=5e-4)   # 0.95, not 1
    assert v[1].max() < 0.96


def test_monolithic_newton_holds_at1_at_its_upper_bound(tmp_path):
    """Below ψ_c every nodal value sits at its bound υ ≤ 1 with a negative gradient: the
    monolithic Newton's active set must hold them all (the free-set tangent in υ would be
    singular there: at1's density is linear in υ)."""
    mono = _run(tmp_path / "mono", "physics.crack_model=at1", "physics.scheme=monolithic",
                "study.max_factor=0.28")
    assert np.all(mono["monolithic_iterations"].values[1:] > 0)
    np.testing.assert_allclose(mono["phase_field"].values, 1.0, rtol=0, atol=1e-14)
    _, r_exact, ratio = _closed_form(mono["load_factor"].values[1:])
    assert ratio.max() < 1
    np.testing.assert_allclose(mono["reaction"].values[1:], r_exact, rtol=5e-4)
