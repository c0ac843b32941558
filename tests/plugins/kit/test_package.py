"""The kit knows no physics and the studies talk to physics only through its protocol: no
module of pointatlas_kit or pointatlas_studies imports a physics plugin (at module level or
inside a function)."""
import ast
from pathlib import Path

import pytest

import pointatlas_kit
import pointatlas_studies


def _absolute_imports(path: Path) -> set[str]:
    out = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and not node.level:
            out.add(node.module)
    return out


@pytest.mark.parametrize("package", [pointatlas_kit, pointatlas_studies],
                         ids=["kit", "studies"])
def test_no_module_imports_a_physics_plugin(package):
    files = sorted(Path(package.__file__).parent.glob("*.py"))
    assert len(files) >= 5
    for path in files:
        bad = sorted(m for m in _absolute_imports(path) if m.startswith("pointatlas_physics"))
        assert not bad, f"{package.__name__}/{path.name} imports {bad}"


def test_the_laplace_beltrami_plugin_is_written_only_against_the_kit():
    from pointatlas_physics.laplace_beltrami import plugin

    mods = _absolute_imports(Path(plugin.__file__))
    assert not [m for m in mods if m.startswith(("pointatlas_physics", "pointatlas_atlas",
                                                 "pointatlas_solvers"))]
    assert len(Path(plugin.__file__).read_text().splitlines()) < 100
