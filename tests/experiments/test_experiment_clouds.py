"""Every shipped physics experiment's cloud passes the checks its physics runs first (issue
16: creases, sheets, components, isolated points) with the experiment's own atlas settings,
so that a change to the checks cannot leave an experiment refused unnoticed (it once did:
shell_pipes, 17f7be7). The bunny experiments are refused on purpose (tests/experiments/
test_bunny.py)."""
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

import pointatlas

EXPERIMENTS = Path(__file__).resolve().parents[2] / "experiments"
REFUSED = {"shell_bunny"}


def _physics_experiments():
    for path in sorted(EXPERIMENTS.glob("*.yaml")):
        text = path.read_text()
        if ("override /physics:" in text and path.stem not in REFUSED
                and "override /physics: stokes_axisymmetric" not in text   # no cloud: BEM
                and "override /source: null" not in text):                 # no cloud at all
            yield path.stem


@pytest.mark.parametrize("name", list(_physics_experiments()))
def test_the_experiment_cloud_passes_its_physics_checks(tmp_path, run_cli, name):
    from pointatlas.pointcloud import PointCloud
    from pointatlas_kit.surface_model import check_surface_cloud

    out = run_cli("pointatlas", f"experiment={name}", "--cfg", "job", cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-2000:]
    cfg = yaml.safe_load(out.stdout)
    source = re.search(r"override /source:\s*(\w+)", (EXPERIMENTS / f"{name}.yaml").read_text())
    cls = pointatlas.load_plugin("sources", source.group(1))
    fields = set(getattr(cls.Config, "__dataclass_fields__", {}))
    cloud = cls(**{k: v for k, v in cfg["source"].items() if k in fields}).load(
        np.random.default_rng(cfg.get("seed", 0)))
    atlas = cfg["atlas"]
    check_surface_cloud(PointCloud(points=cloud.points, name=name), atlas["graph_neighbors"],
                        atlas.get("allow_creases", False))
