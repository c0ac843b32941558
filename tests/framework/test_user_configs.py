"""A user's own experiments through Hydra's --config-dir and hydra.searchpath."""
from pathlib import Path

import pytest
import xarray as xr

from pointatlas.errors import ConfigError
from pointatlas.user_configs import searchpath_override, user_config_dirs

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture
def mine(tmp_path):
    folder = tmp_path / "mine"
    (folder / "experiment").mkdir(parents=True)
    text = (REPO / "experiments" / "shell_plate.yaml").read_text()
    assert "n_points: 441" in text
    (folder / "experiment" / "coarse_plate.yaml").write_text(
        text.replace("n_points: 441", "n_points: 121").replace("title: ", "title: coarse "))
    return folder


def test_config_dirs_from_every_spelling(mine, tmp_path):
    other = tmp_path / "other"
    other.mkdir()
    argv = ["--config-dir", str(mine), f"-cd={other}", "experiment=x",
            f"hydra.searchpath=[file://{other},pkg://somewhere]"]
    assert user_config_dirs(argv) == [mine.resolve(), other.resolve(), other.resolve()]
    assert user_config_dirs(["experiment=x"]) == []
    assert searchpath_override([mine]) == [f"hydra.searchpath=[file://{mine}]"]


def test_a_missing_folder_and_a_headerless_experiment_are_refused(mine, tmp_path):
    with pytest.raises(ConfigError, match="does not exist"):
        user_config_dirs(["--config-dir", str(tmp_path / "nope")])
    (mine / "experiment" / "bad.yaml").write_text("title: no header\n")
    with pytest.raises(ConfigError, match="# @package _global_"):
        user_config_dirs(["--config-dir", str(mine)])


def test_cli_composes_a_user_experiment_both_ways(run_cli, mine, tmp_path):
    for flags in (["--config-dir", str(mine)], [f"hydra.searchpath=[file://{mine}]"]):
        out = run_cli("pointatlas", *flags, "experiment=coarse_plate", "--cfg", "job",
                      cwd=tmp_path)
        assert out.returncode == 0, out.stderr[-2000:]
        assert "n_points: 121" in out.stdout and "title: coarse" in out.stdout
    out = run_cli("pointatlas", "--config-dir", str(mine), "experiment=coarse_plat", cwd=tmp_path)
    assert out.returncode == 2 and "coarse_plate" in out.stderr and "Traceback" not in out.stderr


def test_a_user_experiment_runs_and_replaces_a_shipped_name(run_cli, mine, tmp_path):
    (mine / "experiment" / "shell_plate.yaml").write_text(
        (mine / "experiment" / "coarse_plate.yaml").read_text())
    out = run_cli("pointatlas", "--config-dir", str(mine), "experiment=shell_plate",
                  f"outputs_root={tmp_path / 'out'}", cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-2000:]
    ds = xr.open_dataset(next((tmp_path / "out" / "runs").glob("*/*/results.nc")))
    assert int(ds["point"].size) == 121
    assert abs(float(ds["displacement"]) - 1.2257) < 3e-3
