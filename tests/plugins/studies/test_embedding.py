"""The embedding study on a swiss roll: Isomap recovers the intrinsic coordinates."""
import numpy as np

from pointatlas.context import RunContext
from pointatlas.results import check_variables
from pointatlas_studies.embedding import EmbeddingStudy, parameter_correlation


def test_parameter_correlation_ignores_rotation_and_scale():
    rng = np.random.default_rng(0)
    P = rng.random((200, 2))
    R = np.array([[0.0, -3.0], [2.0, 0.5]])
    assert parameter_correlation(P @ R + 7.0, P) > 1 - 1e-12
    assert parameter_correlation(rng.random((200, 2)), P) < 0.3


def test_isomap_unrolls_swiss_roll(tmp_path):
    ctx = RunContext(config={"source": {"n_points": 1000}, "embedder": {"n_neighbors": 12}},
                     choices={"source": "swiss_roll", "embedder": "isomap", "study": "embedding"},
                     seed=0, run_dir=tmp_path)
    ds = EmbeddingStudy().run(ctx)
    check_variables(ds)
    assert float(ds["parameter_correlation"]) > 0.99
    assert float(ds["trustworthiness"]) > 0.99
    pca = RunContext(config={"source": {"n_points": 1000}},
                     choices={"source": "swiss_roll", "embedder": "pca"}, seed=0, run_dir=tmp_path)
    assert float(EmbeddingStudy().run(pca)["parameter_correlation"]) < 0.9  # PCA cannot unroll it
