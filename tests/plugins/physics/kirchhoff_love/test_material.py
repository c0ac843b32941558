import numpy as np
import pytest

from pointatlas.errors import ConfigError
from pointatlas_physics.kirchhoff_love.material import (
    ShellMaterial, elasticity_tensor, inverse_metric, voigt_elasticity)


@pytest.mark.parametrize("kwargs, word", [
    (dict(young_modulus=1.0, poisson_ratio=0.3, thickness=0.0), "thickness"),
    (dict(young_modulus=-1.0, poisson_ratio=0.3, thickness=0.1), "young_modulus"),
    (dict(young_modulus=1.0, poisson_ratio=0.5, thickness=0.1), "poisson_ratio"),
    (dict(young_modulus=1.0, poisson_ratio=-1.0, thickness=0.1), "poisson_ratio"),
    (dict(young_modulus=float("nan"), poisson_ratio=0.3, thickness=0.1), "young_modulus"),
    (dict(young_modulus="1", poisson_ratio=0.3, thickness=0.1), "young_modulus"),
])
def test_bad_material_raises_config_error_naming_value(kwargs, word):
    with pytest.raises(ConfigError, match=word):
        ShellMaterial(**kwargs).check()


def test_good_material_and_rigidities():
    m = ShellMaterial(young_modulus=2.0, poisson_ratio=0.25, thickness=0.1).check()
    assert m.bending_rigidity == pytest.approx(2.0 * 1e-3 / (12 * (1 - 0.0625)))
    assert m.membrane_rigidity == pytest.approx(0.2 / (1 - 0.0625))


def test_voigt_matches_tensor_contraction_and_plane_stress():
    rng = np.random.default_rng(0)
    T = rng.standard_normal((2, 3))
    A = T @ T.T
    G = inverse_metric(A)
    assert np.allclose(G @ A, np.eye(2))
    C = elasticity_tensor(G, 3.0, 0.2)
    D = voigt_elasticity(G, 3.0, 0.2)
    eps = rng.standard_normal((2, 2))
    eps = eps + eps.T
    e = np.array([eps[0, 0], eps[1, 1], 2 * eps[0, 1]])
    assert np.einsum("abcd,ab,cd", C, eps, eps) == pytest.approx(e @ D @ e)
    D0 = voigt_elasticity(np.eye(2), 3.0, 0.2)  # Cartesian: classical plane stress
    ref = 3.0 / (1 - 0.04) * np.array([[1, 0.2, 0], [0.2, 1, 0], [0, 0, 0.4]])
    assert np.allclose(D0, ref)
