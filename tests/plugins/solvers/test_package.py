"""The shared solvers know no physics: no module of pointatlas_solvers imports a physics (or
study) plugin, at module level or inside a function, and their own imports form no cycle."""
import ast
from pathlib import Path

import pointatlas_solvers

PACKAGE = Path(pointatlas_solvers.__file__).parent
ALLOWED = ("numpy", "scipy", "numba", "pyamg", "pypardiso", "pointatlas", "__future__", "dataclasses",
           "typing", "time", "os", "importlib", "functools")


def _imports(path: Path):
    """(absolute module names, sibling modules imported relatively) of one source file."""
    absolute, relative = set(), set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            absolute.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                relative.update([node.module] if node.module else
                                [a.name for a in node.names])
            else:
                absolute.add(node.module)
    return absolute, relative


def test_no_module_imports_a_physics_or_study_plugin():
    files = sorted(PACKAGE.glob("*.py"))
    assert len(files) >= 10
    for path in files:
        absolute, _ = _imports(path)
        foreign = sorted(m for m in absolute
                         if m.split(".")[0] not in ALLOWED
                         or m.startswith(("pointatlas_physics", "pointatlas_studies")))
        assert not foreign, f"{path.name} imports {foreign}"


def test_the_modules_import_each_other_without_a_cycle():
    graph = {p.stem: _imports(p)[1] for p in PACKAGE.glob("*.py")}
    assert graph["path_following"] >= {"load_control", "arc_length"}
    done, active = set(), []

    def visit(m):
        assert m not in active, f"import cycle: {' -> '.join([*active, m])}"
        if m in done:
            return
        active.append(m)
        for n in graph.get(m, ()):
            visit(n)
        active.pop()
        done.add(m)

    for m in graph:
        visit(m)
