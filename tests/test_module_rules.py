"""Rules every module of `pbp_drake` keeps: modules grouped by topic, one over 600 lines
saying in its docstring why it is one module; imports at the top (except heavy optional
packages deferred on purpose) and pointing one way, from the tools down to the math; no two
modules sharing a file name but those the design page names as one concept in two layers.
The harness beside it, `pbp_drake_bench`, keeps the first two; the library never imports it
but where `pbp-drake bench` hands over to it."""

import ast
import collections
import pathlib
import subprocess
import sys

import pytest

REPO = pathlib.Path(__file__).resolve().parents[1]
PACKAGE = REPO / "pbp_drake"
MODULES = sorted(path for path in PACKAGE.rglob("*.py") if "_models" not in path.parts)
BENCH = REPO / "pbp_drake_bench"
BENCH_MODULES = sorted(BENCH.glob("*.py"))
# Imports a module may defer into a function: heavy optional packages, on purpose.
# scipy.stats: a dependency, but 0.7 s to import; only a user study's report needs it.
# scipy.linalg.blas: 0.2 s to import; only the six-DoF bank's fused step needs its dgemm.
# matplotlib: 0.4 s to import; only the figures' drawing needs it (not a run, nor a trial).
DEFERRED_IMPORTS = {"ray", "pydmps", "movement_primitives.dmp", "threadpoolctl", "scipy.stats",
                    "scipy.linalg.blas", "matplotlib", "matplotlib.cm", "matplotlib.colors",
                    "matplotlib.figure", "matplotlib.patches"}
# The harness, imported by `pbp-drake bench` alone (cli.py), when run.
HARNESS = "pbp_drake_bench.main"


def test_the_package_has_modules():
    assert len(MODULES) > 40


@pytest.mark.slow
@pytest.mark.parametrize("path", MODULES + BENCH_MODULES,
                         ids=lambda path: str(path.relative_to(REPO)))
def test_a_long_module_says_why_and_imports_are_at_the_top(path):
    text = path.read_text()
    tree = ast.parse(text)
    if len(text.splitlines()) > 600:
        assert "one module" in (ast.get_docstring(tree) or "").lower(), (
            f"{path.name} is over 600 lines and its docstring does not say why it is one module")
    top = set(map(id, tree.body))
    for node in ast.walk(tree):
        if isinstance(node, (ast.Import, ast.ImportFrom)) and id(node) not in top:
            modules = ([node.module] if isinstance(node, ast.ImportFrom)
                       else [alias.name for alias in node.names])
            allowed = DEFERRED_IMPORTS | ({HARNESS} if path == PACKAGE / "cli.py" else set())
            assert set(modules) <= allowed, (
                f"{path.name}:{node.lineno} imports {modules} inside a function")


# The layers, from the math up: a module imports only from its own layer and those below.
LAYERS = [{"core"}, {"systems"}, {"robots"}, {"scenarios"}, {"builder"}, {"studies"},
          {"console"}, {"draw", "output_paths", "cli_types"}, {"commands"},
          {"cli"}, {"__main__", "__init__"}]
RANK = {name: rank for rank, names in enumerate(LAYERS) for name in names}


def _layer(path):
    return path.relative_to(PACKAGE).parts[0].removesuffix(".py")


def _imported_layers(tree):
    for node in ast.walk(tree):
        names = ([node.module] if isinstance(node, ast.ImportFrom) and node.module
                 else [a.name for a in node.names] if isinstance(node, ast.Import) else [])
        for name in names:
            if name.startswith("pbp_drake."):
                yield name.split(".")[1], node.lineno


@pytest.mark.parametrize("path", MODULES, ids=lambda path: str(path.relative_to(PACKAGE)))
def test_imports_point_down_the_layers(path):
    layer = _layer(path)
    assert layer in RANK, f"{path.name}: the layer {layer!r} is not in LAYERS"
    for imported, line in _imported_layers(ast.parse(path.read_text())):
        assert RANK[imported] <= RANK[layer], (
            f"{path.relative_to(PACKAGE)}:{line} imports pbp_drake.{imported}, a layer above")


def test_the_systems_folder_is_grouped_by_topic():
    entries = [p for p in (PACKAGE / "systems").iterdir() if p.name != "__pycache__"]
    assert len(entries) <= 12, sorted(p.name for p in entries)


# One concept in two or three layers (the math, the system, the diagram or the command):
# the design page says which is which.
SHARED_NAMES = {"driver_sim.py", "hand_over.py", "point_robot.py", "questionnaire.py", "run.py"}


def test_modules_share_a_file_name_only_as_one_concept_in_different_layers():
    names = collections.Counter(path.name for path in MODULES)
    shared = {name for name, count in names.items() if count > 1
              and name not in {"__init__.py", "__main__.py"}}
    assert shared <= SHARED_NAMES, f"modules sharing a file name: {sorted(shared - SHARED_NAMES)}"
    design = (REPO / "docs" / "design.md").read_text()
    for name in shared:
        for path in MODULES:
            if path.name == name:
                assert str(path.relative_to(PACKAGE)) in design, (
                    f"docs/design.md does not say which {name} is which "
                    f"({path.relative_to(PACKAGE)})")


@pytest.mark.slow
@pytest.mark.parametrize("path", MODULES, ids=lambda path: str(path.relative_to(PACKAGE)))
def test_the_library_does_not_import_the_harness_at_the_top(path):
    tree = ast.parse(path.read_text())
    for node in tree.body:
        names = ([node.module or ""] if isinstance(node, ast.ImportFrom)
                 else [a.name for a in node.names] if isinstance(node, ast.Import) else [])
        assert not any(name.split(".")[0] == BENCH.name for name in names), (
            f"{path.relative_to(PACKAGE)}:{node.lineno} imports the harness")


def modules_loaded(imports, prefixes):
    """The modules whose names start with one of `prefixes` that a fresh Python has loaded
    after `import` of `imports` (names, comma-separated), sorted."""
    code = (f"import sys, {imports}; print(sorted(name for name in sys.modules "
            f"if name.startswith({tuple(prefixes)!r})))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            cwd=REPO, timeout=120)
    assert result.returncode == 0, result.stderr
    return result.stdout.strip()


@pytest.mark.slow
def test_the_harness_imports_the_library_not_the_other_way():
    # Loading the command line and every topic leaves the harness unloaded.
    assert modules_loaded("pbp_drake, pbp_drake.cli, pbp_drake.builder, pbp_drake.studies",
                          ["pbp_drake_bench"]) == "[]"
    assert BENCH_MODULES, "the harness package is missing"


@pytest.mark.slow
def test_the_command_line_starts_without_matplotlibs_figures():
    # `pbp-drake run` (and `study` before its report) loads no figure, axes or 3-D toolkit:
    # 0.4 s sooner. (pydrake.visualization loads matplotlib's colours, which are light.)
    assert modules_loaded("pbp_drake.cli, pbp_drake.commands.run, pbp_drake.commands.study",
                          ["matplotlib.figure", "matplotlib.axes", "matplotlib.pyplot",
                           "mpl_toolkits"]) == "[]"
