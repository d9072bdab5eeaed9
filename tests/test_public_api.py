"""One way in: every public name imports from `pbp_drake`, and the tutorials, the README and
the docs' examples import from `pbp_drake` alone, never from its insides."""

import json
import pathlib
import re
import subprocess
import sys

import pytest

import pbp_drake

REPO = pathlib.Path(__file__).resolve().parents[1]
# `from pbp_drake.x import ...` or `import pbp_drake.x`: a deep path.
DEEP_IMPORT = re.compile(r"^\s*(?:from\s+pbp_drake\.[\w.]+\s+import|import\s+pbp_drake\.)", re.M)
FENCE = re.compile(r"```(?:python|py)\n(.*?)```", re.S)


def _notebook_code(path):
    cells = json.loads(path.read_text())["cells"]
    return "\n".join("".join(cell["source"]) for cell in cells if cell["cell_type"] == "code")


def _examples():
    for path in sorted((REPO / "tutorials").glob("*.ipynb")):
        yield path, _notebook_code(path)
    pages = [REPO / "README.md", *sorted((REPO / "docs").rglob("*.md"))]
    for path in pages:
        if "_build" not in path.parts:
            yield path, "\n".join(FENCE.findall(path.read_text()))


@pytest.mark.parametrize("name", pbp_drake.__all__)
def test_every_public_name_imports_from_the_package(name):
    assert getattr(pbp_drake, name) is not None


def test_every_public_name_has_a_topic():
    grouped = [name for group in pbp_drake.API_GROUPS.values() for name in group]
    assert len(grouped) == len(set(grouped)), "a name stands in two topics"
    assert set(pbp_drake.__all__) == {"__version__", *grouped}


def test_a_public_submodule_imports_from_a_fresh_interpreter():
    # Here other tests have imported pbp_drake.core.quaternion; there nothing has.
    code = ("import sys, pbp_drake; assert 'pbp_drake.core.quaternion' not in sys.modules; "
            "print(pbp_drake.quaternion.__name__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out == "pbp_drake.core.quaternion\n"


@pytest.mark.slow
def test_drawing_figures_keeps_the_users_matplotlib_backend(tmp_path):
    # A notebook's inline figures vanish if importing or drawing switches the backend.
    code = ("import matplotlib; matplotlib.use('svg'); import sys; "
            "from pbp_drake import phase_progress, report, teach_primitive; "
            "from pbp_drake.studies.primitive_figure import plot_primitive; "
            "import pbp_drake.studies.questionnaire_figure; import numpy as np; "
            "times = np.linspace(0, 1, 50); path = np.outer(times, [1.0, 0.5, 0.0]); "
            "plot_primitive(teach_primitive(times, path), path[-1:] + 0.1, sys.argv[1]); "
            "print(matplotlib.get_backend())")
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "primitive.png")],
                         capture_output=True, text=True, check=True).stdout
    assert out == "svg\n"
    assert (tmp_path / "primitive.png").read_bytes().startswith(b"\x89PNG")


def test_dir_lists_every_public_name():
    assert set(pbp_drake.__all__) <= set(dir(pbp_drake))


def test_an_unknown_name_says_so():
    with pytest.raises(AttributeError, match="no attribute 'NoSuchThing'"):
        pbp_drake.NoSuchThing  # noqa: B018


def test_a_controller_of_your_own_asks_whether_its_method_has_a_forward_key():
    # Tutorial 08 wires the operator's forward key from it: teleop needs the key.
    from pbp_drake import PbpControllerConfig, forward_key_enabled

    assert forward_key_enabled(PbpControllerConfig(method="teleop"))
    assert not forward_key_enabled(PbpControllerConfig(method="pbp_alternated"))


@pytest.mark.parametrize("path, code", list(_examples()),
                         ids=lambda value: value.name if isinstance(value, pathlib.Path) else "")
def test_examples_import_only_public_names(path, code):
    deep = [line.strip() for line in code.splitlines() if DEEP_IMPORT.match(line)]
    assert not deep, f"{path.relative_to(REPO)} imports from inside the package: {deep}"
    for grouped, single in re.findall(r"from pbp_drake import (?:\(([^)]*)\)|([^\n(]+))", code):
        for name in filter(None, (n.strip() for n in (grouped or single).split(","))):
            assert name in pbp_drake.__all__, f"{path.relative_to(REPO)}: {name} is not public"
