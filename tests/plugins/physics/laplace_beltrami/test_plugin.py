"""laplace_beltrami end to end against analytic solutions (closed sphere, open plane)."""
import numpy as np

from pointatlas import open_run


def test_sphere_harmonic_at_1000_points(tmp_path, run_cli):
    """−Δu + u = 13 Y on the unit sphere, Y = (x² − y²) z / r³ (degree 3): u = Y.
    Measured 4.33e-3 (L2) / 2.23e-2 (H1) at 1 000 points (experiment header)."""
    r = run_cli("pointatlas", "experiment=laplace_beltrami_sphere", "source.n_points=1000",
                "study.refinement=[]", f"outputs_root={tmp_path}/out", "quiet=true",
                cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    ds = open_run(next((tmp_path / "out").glob("runs/*/*")))
    assert float(ds["l2_error"]) < 6e-3 and float(ds["h1_error"]) < 3e-2
    assert ds["u"].dims == ("point",) and ds.sizes["point"] == 1000


def test_the_refinement_study_writes_its_convergence_table(tmp_path, run_cli):
    """study.refinement (the experiment's default runs 1 000 to 20 000 points; it used to fail
    at the very end writing its results: the `refinement` coordinate had no units): errors
    fall from 600 to 1 200 points at about the experiment header's rate (≈ 2 in h)."""
    r = run_cli("pointatlas", "experiment=laplace_beltrami_sphere", "source.n_points=600",
                "study.refinement=[600,1200]", f"outputs_root={tmp_path}/out", "quiet=true",
                cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    ds = open_run(next((tmp_path / "out").glob("runs/*/*")))
    assert ds["refinement"].attrs["units"] == "1"
    assert ds["refinement_points"].values.tolist() == [600, 1200]
    err = ds["refinement_l2_error"].values
    assert err[1] < err[0] and float(ds["refinement_l2_error"][0]) == float(ds["l2_error"])
    assert np.isnan(ds["refinement_l2_rate"].values[0])
    assert 1.0 < float(ds["refinement_l2_rate"].values[1]) < 3.5


def test_dirichlet_values_on_a_jittered_square(tmp_path, run_cli):
    """Δu = 0 on the plane with u = x² − y² + xy on the boundary (an expression): the
    harmonic u itself; the supports hold every boundary point at its value (a box around
    the square selects the whole boundary)."""
    rng = np.random.default_rng(3)
    g = np.linspace(0.0, 1.0, 21)
    xy = np.array(np.meshgrid(g, g, indexing="ij")).reshape(2, -1).T
    inner = ((xy > 0) & (xy < 1)).all(axis=1)
    xy[inner] += 0.2 / 20 * rng.uniform(-1, 1, (int(inner.sum()), 2))
    np.savez(tmp_path / "square.npz", points=np.column_stack([xy, np.zeros(len(xy))]))
    exact = "x**2 - y**2 + x*y"
    r = run_cli("pointatlas", "~experiment", "source=file", f"source.path={tmp_path}/square.npz",
                "embedder=pca", "physics=laplace_beltrami", "study=surface_pde",
                "physics.c=0", "physics.source_term=0",
                f"physics.supports=[{{where:{{box:[-1,-1,-1,2,2,1]}},value:'{exact}'}}]",
                f"study.exact='{exact}'", f"outputs_root={tmp_path}/out", "quiet=true",
                cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    ds = open_run(next((tmp_path / "out").glob("runs/*/*")))
    u = ds["u"].values
    x, y = xy.T
    on_edge = ~inner
    assert np.abs(u[on_edge] - (x**2 - y**2 + x * y)[on_edge]).max() < 1e-6
    assert float(ds["constraint_violation"]) < 1e-8
    # measured 2.13e-3 / 5.18e-2 (441 points; the LME basis reproduces linear functions
    # only, so a quadratic u is approximated to O(h²))
    assert float(ds["l2_error"]) < 4e-3 and float(ds["h1_error"]) < 8e-2
