"""The atlas choices a physics cannot use are refused with the fix named (CLI, one line)."""


def test_an_approximant_that_cannot_be_a_chart_basis_is_refused(run_cli, tmp_path):
    r = run_cli("pointatlas", "experiment=shell_plate", "approximant=shepard",
                "source.n_points=100", f"hydra.run.dir={tmp_path}/a", cwd=tmp_path)
    assert r.returncode != 0
    assert "approximant=shepard cannot be the basis of the atlas charts" in r.stderr + r.stdout
    assert "Traceback" not in r.stderr


def test_an_approximant_gamma_the_charts_do_not_use_is_refused(run_cli, tmp_path):
    r = run_cli("pointatlas", "experiment=shell_plate", "approximant=lme",
                "approximant.gamma=2.5", "source.n_points=100", f"hydra.run.dir={tmp_path}/b",
                cwd=tmp_path)
    assert r.returncode != 0
    assert "Write atlas.gamma_lme=2.5 instead" in r.stderr + r.stdout


def _sphere(n, centre=(0.0, 0.0, 0.0)):
    """A Fibonacci sphere made here (not by a project source)."""
    import numpy as np

    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    phi = np.pi * (1 + 5 ** 0.5) * i
    r = np.sqrt(1 - z * z)
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z]) + np.asarray(centre)


def test_a_physics_refuses_creases_and_several_components():
    import numpy as np
    import pytest

    from pointatlas.errors import InputError
    from pointatlas.pointcloud import PointCloud
    from pointatlas_kit.surface_model import check_surface_cloud

    from ..atlas.test_cloud_checks import cube_surface

    check_surface_cloud(PointCloud(points=_sphere(800), name="sphere"), 10)  # smooth: passes
    cube = PointCloud(points=cube_surface(14), name="cube")
    with pytest.raises(InputError, match="creases.*set atlas.allow_creases=true"):
        check_surface_cloud(cube, 10)
    # kept on request: the reason comes back as the warning the results carry
    kept = check_surface_cloud(cube, 10, allow_creases=True)
    assert kept.startswith("cube: kept by atlas.allow_creases=true, but this cloud has creases")
    assert check_surface_cloud(PointCloud(points=_sphere(800), name="sphere"), 10, True) is None
    two = np.vstack([_sphere(600), _sphere(600, (5.0, 0.0, 0.0))])
    with pytest.raises(InputError, match="2 connected components.*one connected surface"):
        check_surface_cloud(PointCloud(points=two, name="two spheres"), 10, allow_creases=True)
