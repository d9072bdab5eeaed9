"""Rules every module of `pbp_drake` keeps: at most 450 lines, one job; imports at the top,
except heavy optional packages deferred on purpose."""

import ast
import pathlib

import pytest

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / "pbp_drake"
MODULES = sorted(path for path in PACKAGE.rglob("*.py") if "_models" not in path.parts)
# Imports a module may defer into a function: heavy optional packages, on purpose.
# scipy.stats: a dependency, but 0.7 s to import; only a user study's report needs it.
# scipy.linalg.blas: 0.2 s to import; only the six-DoF bank's fused step needs its dgemm.
DEFERRED_IMPORTS = {"ray", "pydmps", "movement_primitives.dmp", "threadpoolctl", "scipy.stats",
                    "scipy.linalg.blas"}


def test_the_package_has_modules():
    assert len(MODULES) > 40


@pytest.mark.parametrize("path", MODULES, ids=lambda path: str(path.relative_to(PACKAGE)))
def test_module_is_short_and_imports_at_the_top(path):
    text = path.read_text()
    assert len(text.splitlines()) <= 450, f"{path.name} is over 450 lines"
    tree = ast.parse(text)
    top = set(map(id, tree.body))
    for node in ast.walk(tree):
        if isinstance(node, (ast.Import, ast.ImportFrom)) and id(node) not in top:
            modules = ([node.module] if isinstance(node, ast.ImportFrom)
                       else [alias.name for alias in node.names])
            assert set(modules) <= DEFERRED_IMPORTS, (
                f"{path.name}:{node.lineno} imports {modules} inside a function")
