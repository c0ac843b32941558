"""rom_snapshots as a two-seed multirun at a tiny size, gathered by pointatlas.open_sweep."""
import numpy as np


def test_two_trajectories_gathered_along_seed(run_cli, tmp_path):
    import pointatlas

    out = run_cli("pointatlas", "experiment=rom_snapshots", "seed=0,1",
                  "physics.n_triangles=200", "physics.n_steps=500", "physics.save_every=50",
                  f"outputs_root={tmp_path}", "-m", cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    ds = pointatlas.open_sweep(next(tmp_path.glob("multirun/*/*")))
    assert ds["position"].dims == ("seed", "time", "node", "dim")
    assert ds.sizes["seed"] == 2 and ds.sizes["time"] == 11
    a, b = ds["initial_load"].values                  # the seed sets the initial condition
    assert not np.allclose(a, b)
    assert float(ds["energy_error"].max()) < 1e-3
