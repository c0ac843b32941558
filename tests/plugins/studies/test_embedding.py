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


# -- too few points: one line before any work (issue 15) ----------------------------------

import pytest  # noqa: E402

from pointatlas.errors import InputError  # noqa: E402


def _file_context(tmp_path, embedder, n_points, **config):
    path = tmp_path / "few.npz"
    np.savez(path, points=np.random.default_rng(0).normal(size=(n_points, 3)))
    return RunContext(config={"source": {"path": str(path)}, **config},
                      choices={"source": "file", "embedder": embedder, "study": "embedding"},
                      seed=0, run_dir=tmp_path)


@pytest.mark.parametrize("embedder", ["pca", "isomap", "lle", "mlle", "nlie"])
def test_three_points_are_refused_with_the_needs_and_the_fix(tmp_path, embedder, monkeypatch):
    ctx = _file_context(tmp_path, embedder, 3)
    called = []
    monkeypatch.setattr(type(ctx.plugin("embedder")), "fit_transform",
                        lambda self, X: called.append(X))
    with pytest.raises(InputError) as info:
        EmbeddingStudy().run(ctx)
    msg = str(info.value)
    assert msg.startswith(f"3 points are too few for the embedding study with {embedder}: ")
    assert "study.stress_neighbors=12 needs 13 (stress_neighbors + 1)" in msg
    assert "study.trustworthiness_neighbors=12 needs 25 (2 trustworthiness_neighbors + 1)" in msg
    assert ("embedder.n_neighbors=12 needs 13 (n_neighbors + 1)" in msg) == (embedder != "pca")
    assert "Give at least 25 points" in msg and "study.trustworthiness_neighbors=1)" in msg
    assert "\n" not in msg and not called  # refused before the embedder ran


def test_the_suggested_settings_fit(tmp_path):
    """The values the refusal suggests for 5 points do run (PCA: no graph of its own)."""
    ctx = _file_context(tmp_path, "pca", 5)
    with pytest.raises(InputError, match=r"study.stress_neighbors=4, "
                                         r"study.trustworthiness_neighbors=2\)"):
        EmbeddingStudy().run(ctx)
    ds = EmbeddingStudy(stress_neighbors=4, trustworthiness_neighbors=2).run(
        _file_context(tmp_path, "pca", 5))
    assert ds.sizes["point"] == 5 and 0.0 <= float(ds["trustworthiness"]) <= 1.0


def test_enough_points_pass_the_check(tmp_path):
    ds = EmbeddingStudy(stress_neighbors=12, trustworthiness_neighbors=12).run(
        _file_context(tmp_path, "isomap", 25))
    assert ds.sizes["point"] == 25 and np.isfinite(float(ds["stress"]))
