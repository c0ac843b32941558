"""``pointatlas --help``: the config groups and their choices, without composing anything.

Hydra's own help composes the config once per group option (seconds with many plugins);
this one reads the registry and the config folders only, so it answers at once.
"""
from __future__ import annotations

from .config import CONF_DIR, experiment_usage, experiments
from .registry import FAMILIES, discover

USAGE = """\
pointatlas: compute on manifolds known only through scattered points.

Usage:
  pointatlas [group=option ...] [key=value ...]      run one experiment (default: no arguments)
  pointatlas experiment=NAME [key=value ...]         run a published experiment
  pointatlas --multirun key=a,b,c [...]               sweep (hydra/launcher=local_parallel for 2 cores)
  pointatlas --cfg job [overrides]                    print the composed config without running
  pointatlas --hydra-help                             Hydra's own flags

Top-level keys: seed (int, seeds every random choice), quiet (bool), outputs_root (run
directories and catalog.sqlite), title. A plugin's keys: pointatlas --cfg job GROUP=NAME.
"""


def _yaml_choices(folder) -> list[str]:
    return sorted(p.stem for p in folder.glob("*.yaml")) if folder.is_dir() else []


def help_text() -> str:
    lines = [USAGE, "== Configuration groups (group=option) =="]
    for group, family in FAMILIES.items():
        lines.append(f"{family}: {', '.join(sorted(discover(group))) or '(none installed)'}")
    lines.append(f"sweep: {', '.join(_yaml_choices(CONF_DIR / 'sweep'))}")
    presets = _yaml_choices(CONF_DIR / "hydra" / "launcher")
    lines.append(f"hydra/launcher: basic, joblib, submitit_local, submitit_slurm, {', '.join(presets)}")
    lines.append("experiment:")
    for name, path in sorted(experiments().items()):
        usage = experiment_usage(path)
        lines.append(f"  {name:<22} {usage.partition('(')[2].rstrip(')') if '(' in usage else ''}")
    lines += ["", "Results: <run dir>/results.nc (pointatlas.open_run); runs: pointatlas-runs list;",
              "reports: pointatlas-report <run or sweep dir>."]
    return "\n".join(lines)
