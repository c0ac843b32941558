"""Bad fracture settings: one clear line naming the problem and the fix, before any work."""
import pytest

BASE = ["experiment=fracture_crack_energy", "source.n_points=441", "physics.length_scale=0.1",
        "quiet=true"]


@pytest.mark.parametrize("override, message", [
    ("physics.fracture_toughness=0", "physics.fracture_toughness"),
    ("physics.length_scale=-0.1", "physics.length_scale"),
    ("physics.length_scale=null", "physics.length_scale (κ̄) is not set"),
    ("physics.residual_stiffness=1.5", "physics.residual_stiffness"),
    ("physics.residual_stiffness=0", "physics.residual_stiffness"),
    ("physics.split=amor", "physics.split=amor splits the strain energy"),
    ("physics.split=spectral", "physics.split"),
    ("physics.crack_model=at3", "physics.crack_model"),
    ("physics.kinematics=exact", "physics.kinematics"),
    ("physics.precracks=[{box:[5,5,5,6,6,6]}]", "physics.precracks[0]"),
    ("physics.precracks=[{}]", "has no criterion"),
    ("physics.precracks=[{polyline:[[0,0,0]]}]", "two or more points"),
    ("physics.length_scale=0.01", "smallest κ̄ this cloud supports is 0.1"),
])
def test_bad_settings_are_one_line(tmp_path, run_cli, override, message):
    r = run_cli("pointatlas", *BASE, override, f"outputs_root={tmp_path}/out", cwd=tmp_path)
    assert r.returncode != 0
    err = r.stderr.strip()
    assert "Traceback" not in err, err[-2000:]
    assert message in err, err[-2000:]
    assert len([line for line in err.splitlines() if line.startswith("pointatlas: error")]) == 1


def test_supports_with_the_phase_field_alone_are_refused(tmp_path, run_cli):
    r = run_cli("pointatlas", *BASE,
                "physics.supports=[{kind: clamped, where: {plane: [1, 0, 0, 0.5]}}]",
                f"outputs_root={tmp_path}/out", cwd=tmp_path)
    assert r.returncode != 0 and "kinematics=none solves the phase field alone" in r.stderr


def test_the_split_needs_kinematics_that_drive_the_crack():
    from pointatlas.errors import ConfigError
    from pointatlas_physics.kirchhoff_love_fracture.settings import (FractureSettings,
                                                                     check_fracture_settings)

    with pytest.raises(ConfigError, match="kinematics=none has none"):
        check_fracture_settings(FractureSettings(length_scale=0.1, kinematics="none",
                                                 split="amor"))
    with pytest.raises(ConfigError, match="kinematics=nonlinear has Green-Lagrange ones"):
        check_fracture_settings(FractureSettings(length_scale=0.1, kinematics="nonlinear",
                                                 split="amor"))
    with pytest.raises(ConfigError, match="physics.max_newton"):
        check_fracture_settings(FractureSettings(length_scale=0.1, kinematics="nonlinear",
                                                 max_newton=0))
    with pytest.raises(ConfigError, match="thickness_points"):
        check_fracture_settings(FractureSettings(length_scale=0.1, split="amor",
                                                 thickness_points=1))
