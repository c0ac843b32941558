"""physics.streamed_assembly: the linear shell without the basis kept gives the figures of
the stored basis, and is refused where one assembly is not enough."""
import numpy as np

import pointatlas


def test_the_streamed_hemisphere_is_the_stored_one(run_cli, tmp_path):
    """The pinched hemisphere (quarter model, closed pole) both ways: K differs at round-off
    (other sums), so the displacements agree to the solve's conditioning, not bit for bit."""
    runs = {}
    for tag, extra in (("stored", ()), ("streamed", ("physics.streamed_assembly=true",))):
        r = run_cli("pointatlas", "experiment=shell_hemisphere", "source.n_points=500", *extra,
                    f"hydra.run.dir={tmp_path}/{tag}", cwd=tmp_path)
        assert r.returncode == 0, r.stderr[-3000:]
        runs[tag] = pointatlas.open_run(tmp_path / tag)
    a, b = runs["stored"], runs["streamed"]
    u, v = a["displacement"].values, b["displacement"].values
    assert np.abs(u - v).max() <= 1e-9 * np.abs(u).max()
    assert int(a["n_quadrature_points"]) == int(b["n_quadrature_points"]) > 0
    assert a.attrs["config"] != b.attrs["config"]  # the choice is in the stored config


def test_a_load_path_refuses_streamed_assembly_in_one_line(run_cli, tmp_path):
    r = run_cli("pointatlas", "experiment=shell_pullout", "physics.streamed_assembly=true",
                f"hydra.run.dir={tmp_path}/p", cwd=tmp_path)
    assert r.returncode != 0
    assert ("physics.streamed_assembly=true is for the linear analysis (one assembly); a load "
            "path assembles K at every Newton step") in r.stderr + r.stdout
    assert "Traceback" not in r.stderr


def test_a_linear_model_too_large_for_memory_names_streamed_assembly(monkeypatch):
    """The refusal before any work offers physics.streamed_assembly to the linear analysis,
    not to a load path (which refuses it)."""
    import pytest

    import pointatlas_atlas.memory_estimate as mem
    from pointatlas.errors import InputError
    from pointatlas_atlas.settings import AtlasSettings
    from pointatlas_kit.selectors import Selector
    from pointatlas_kit.surface_model import atlas_factories
    from pointatlas_physics.kirchhoff_love.analysis import build_model
    from pointatlas_physics.kirchhoff_love.settings import Load, ShellSettings, Support

    monkeypatch.setattr(mem, "available_memory_bytes", lambda: (10 * 2**20, "a test limit"))
    cloud = pointatlas.load_plugin("sources", "square_plate")(
        n_points=196, model="quarter", length=10.0).load(np.random.default_rng(0))
    s = ShellSettings(supports=[Support(kind="clamped", where=Selector(plane=[1, 0, 0, 5.0]))],
                      loads=[Load(kind="point", at=[0, 0, 0], force=[0, 0, -1])])
    atlas = AtlasSettings()
    for linear in (True, False):
        with pytest.raises(InputError) as info:
            build_model(cloud, s, atlas, linear=linear, **atlas_factories(None, atlas))
        msg = str(info.value)
        assert "10.00 MiB is available (a test limit)" in msg and "\n" not in msg
        offered = "physics.streamed_assembly=true (a linear analysis that does not keep the " \
                  "basis, most of this memory), or a machine with more memory." in msg
        assert offered == linear, msg
