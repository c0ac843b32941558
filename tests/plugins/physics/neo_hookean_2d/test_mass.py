"""Lumped and consistent mass."""
import numpy as np
import pytest

from pointatlas_physics.neo_hookean_2d.mass import Mass, consistent_mass_matrix, lumped_masses
from pointatlas_physics.neo_hookean_2d.mesh import tapered_column


def test_both_masses_weigh_the_body():
    m = tapered_column(n_triangles=100)
    area = m.areas
    ml = lumped_masses(m.triangles, area, 2.5, m.n_nodes)
    Mc = consistent_mass_matrix(m.triangles, area, 2.5, m.n_nodes)
    assert ml.sum() == pytest.approx(2.5 * area.sum())
    assert np.allclose(Mc.sum(axis=1).A1, ml)            # row sums are the lumped masses
    # the consistent mass integrates the product of two linear fields exactly
    u, w = 1 + m.nodes[:, 0], m.nodes[:, 1]
    exact = 2.5 * np.sum(area * np.mean(w[m.triangles], 1))   # ∫ (1 + x) y dA ...
    exact += 2.5 * sum(a / 12 * (np.sum(m.nodes[t, 0] * w[t]) + np.sum(m.nodes[t, 0]) *
                                 np.sum(w[t])) for a, t in zip(area, m.triangles))
    assert u @ (Mc @ w) == pytest.approx(exact, rel=1e-12)


@pytest.mark.parametrize("kind", ["lumped", "consistent"])
def test_accelerations_and_kinetic_energy(kind):
    m = tapered_column(n_triangles=100)
    free = m.nodes[:, 1] > 0
    M = Mass(kind, m.triangles, m.areas, 1.0, free)
    v = np.tile([0.3, -0.2], (m.n_nodes, 1))
    assert M.kinetic_energy(v) == pytest.approx(0.5 * 0.13 * m.areas.sum())
    r = np.random.default_rng(0).standard_normal((m.n_nodes, 2))
    a = M.accelerations(r)
    assert np.all(a[~free] == 0)
    assert np.allclose(M.apply(a)[free], r[free])          # M_ff a_f = r_f
