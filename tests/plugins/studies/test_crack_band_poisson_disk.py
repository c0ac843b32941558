"""The crack band on a cloud the project did not generate: scipy's Poisson-disk sampler
(Bridson's algorithm, ``scipy.stats.qmc.PoissonDisk``) fills the square [−½, ½]², a row of
points on the crack line x = 0 is added, and the cloud goes through ``source=file``.

Measured (κ̄ = 0.05): at 2 378 points (radius 0.016) crack energy +0.98 % of G_c h L,
profile error 2.08 % of its range away from the edges y = ±½ (at a point 0.011 from the
crack, between the line's points and the disk samples) and 5.6 % at them: the sampler leaves
those edges ragged (no point on them), so the band meets a boundary the cloud does not
resolve. At 5 031 points (radius 0.011): +0.39 %, 1.43 % inside, 5.5 % at the edges. The
issue's 2 % profile bar (met on the project's grid) is missed here at 2 378 points by 0.08 %.
With physics.crack_model=at1 (band 1 − (1 − d/4κ̄)²), at 2 378 points: +0.38 %, 2.41 % inside,
7.1 % at the edges, and every point beyond the band intact to 1.5e-9; at 5 031: +0.097 %,
1.45 % inside, 6.6 % at the edges.
"""
import numpy as np
import pytest

from pointatlas import open_run


@pytest.fixture
def poisson_disk_plate(tmp_path):
    from scipy.stats import qmc

    radius = 0.016
    P = qmc.PoissonDisk(d=2, radius=radius, seed=7).fill_space() - 0.5
    P = P[np.abs(P[:, 0]) > 0.6 * radius]           # room for the crack line's points
    n = int(round(1 / radius))
    line = np.column_stack([np.zeros(n + 1), np.linspace(-0.5, 0.5, n + 1)])
    X = np.vstack([P, line])
    path = tmp_path / "poisson_disk_plate.npz"
    np.savez(path, points=np.column_stack([X, np.zeros(len(X))]))
    return path


def test_crack_band_on_a_poisson_disk_cloud(tmp_path, run_cli, poisson_disk_plate):
    r = run_cli("pointatlas", "experiment=fracture_crack_energy", "source=file",
                f"source.path={poisson_disk_plate}", "source.intrinsic_dim=2",
                f"outputs_root={tmp_path}/out", "quiet=true", cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    ds = open_run(next((tmp_path / "out").glob("runs/*/*")))
    assert 0 < float(ds["relative_error"]) < 0.02
    x, v = ds["position"].values, ds["phase_field"].values
    error = np.abs(v - (1 - np.exp(-np.abs(x[:, 0]) / (2 * 0.05))))
    inner = np.abs(x[:, 1]) < 0.45
    assert error[inner].max() < 0.025              # 0.0208 measured (module doc)
    assert float(ds["profile_error"]) == pytest.approx(error.max(), abs=1e-12)
    assert float(ds["profile_error"]) < 0.08        # the ragged edges (module doc)


def test_the_at1_band_on_the_same_cloud(tmp_path, run_cli, poisson_disk_plate):
    r = run_cli("pointatlas", "experiment=fracture_crack_energy", "source=file",
                f"source.path={poisson_disk_plate}", "source.intrinsic_dim=2",
                "physics.crack_model=at1", f"outputs_root={tmp_path}/out", "quiet=true",
                cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    ds = open_run(next((tmp_path / "out").glob("runs/*/*")))
    assert 0 < float(ds["relative_error"]) < 0.02
    x, v = ds["position"].values, ds["phase_field"].values
    d = np.abs(x[:, 0])
    error = np.abs(v - (1 - np.clip(1 - d / (4 * 0.05), 0, None) ** 2))
    assert error[np.abs(x[:, 1]) < 0.45].max() < 0.03    # 0.0241 measured (module doc)
    assert np.abs(v[d > 0.25] - 1).max() < 1e-8           # beyond the compact band: intact
    assert v.max() <= 1 + 1e-12
