"""Every config group composes, and plugin configs are checked against their dataclass."""
import pytest
from hydra import compose, initialize_config_dir

from pointatlas.config import CONF_DIR, experiments, register_configs
from pointatlas.registry import FAMILIES, load_all

register_configs()


def choices():
    out = []
    for group, family in FAMILIES.items():
        out += [(family, name) for name in load_all(group)]
    out += [("experiment", name) for name in experiments()]
    out += [("sweep", p.stem) for p in (CONF_DIR / "sweep").glob("*.yaml")]
    out += [("hydra/launcher", p.stem) for p in (CONF_DIR / "hydra" / "launcher").glob("*.yaml")]
    return out


@pytest.mark.parametrize("group,name", choices())
def test_every_config_group_composes(group, name):
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        # ~experiment: the default experiment sets keys of its own plugins
        extra = [] if group == "experiment" else ["~experiment"]
        cfg = compose("config", overrides=[f"{group}={name}", *extra], return_hydra_config=True)
    assert cfg.hydra.runtime.choices[group] == name


def test_experiments_have_usage_comment_and_reference():
    for name, path in experiments().items():
        text = path.read_text()
        assert text.startswith("# @package _global_"), name
        assert f"# Usage: pointatlas experiment={name}" in text, name


def test_a_single_run_is_composed_once_and_each_sweep_job_once_more(monkeypatch):
    """Start-up composes a single run's config once (each compose costs a deep copy of the
    whole config store); a sweep composes its first job's base, then each job."""
    from pointatlas import cli

    calls = []
    compose_once = cli._compose
    monkeypatch.setattr(cli, "_compose", lambda overrides: calls.append(overrides) or
                        compose_once(overrides))
    assert cli.check_composition(["experiment=sphere_willmore", "source.n_points=300"]) is False
    assert calls == [["experiment=sphere_willmore", "source.n_points=300"]]
    calls.clear()
    assert cli.check_composition(["experiment=sphere_willmore", "source.n_points=300,400"],
                                 multirun=True) is True
    assert calls == [["experiment=sphere_willmore"],
                     ["experiment=sphere_willmore", "source.n_points=300"],
                     ["experiment=sphere_willmore", "source.n_points=400"]]
