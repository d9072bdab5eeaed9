"""Every tutorial notebook runs headless, the way Drake and manipulation test theirs: with
the short-run switch (`PBP_SHORT_RUN=1`) and Drake's deprecation warnings as errors. The
notebooks are stored with their outputs stripped."""

import os
import pathlib
import sys

import pytest

if os.environ.get("CI"):  # the test extra is installed there: never skip
    import ipykernel  # noqa: F401
    import nbclient
    import nbformat
else:
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")

# Whole tasks, studies, notebooks, browsers or pip: `make test-fast` leaves these out.
pytestmark = pytest.mark.slow

TUTORIALS = pathlib.Path(__file__).resolve().parents[2] / "tutorials"
NOTEBOOKS = sorted(TUTORIALS.glob("*.ipynb"))
EXPECTED = ["01_dmp_basics", "02_policy_blending_2d", "03_hsr_multi_goal",
            "04_build_your_own_diagram", "05_run_a_study", "06_hsr_station",
            "07_orientation_primitives", "08_pbp_on_your_urdf", "09_teach_a_primitive"]

# Run first in every notebook's kernel.
STRICT_WARNINGS = """\
import warnings
from pydrake.common.deprecation import DrakeDeprecationWarning

warnings.simplefilter("error", DrakeDeprecationWarning)
"""


def test_every_tutorial_is_there():
    assert [path.stem for path in NOTEBOOKS] == EXPECTED


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_notebook_is_stored_without_outputs(path):
    notebook = nbformat.read(path, as_version=4)
    nbformat.validate(notebook)
    assert notebook.cells[0].cell_type == "markdown"
    assert "What it teaches" in notebook.cells[0].source
    assert "make tutorials" in notebook.cells[0].source
    for cell in notebook.cells:
        if cell.cell_type == "code":
            assert cell.outputs == [] and cell.execution_count is None, cell.source[:60]


def _indented_lines(markdown):
    """The lines of a Markdown text that start with four spaces outside fenced code blocks:
    Markdown shows them as code (a title so indented renders as a code block)."""
    indented, fenced = [], False
    for line in markdown.splitlines():
        if line.lstrip().startswith(("```", "~~~")):
            fenced = not fenced
        elif not fenced and line.startswith("    "):
            indented.append(line)
    return indented


def test_the_indentation_check_tells_code_from_text():
    assert _indented_lines("    # 01 · DMP basics\n\ntext") == ["    # 01 · DMP basics"]
    assert _indented_lines("text\n```sh\n    make demo\n```\n1. item\n   more") == []


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_markdown_cells_render_as_text_not_code(path):
    notebook = nbformat.read(path, as_version=4)
    for index, cell in enumerate(notebook.cells):
        if cell.cell_type == "markdown":
            assert not _indented_lines(cell.source), (
                f"cell {index} has lines indented by four spaces, which render as a code "
                f"block: {_indented_lines(cell.source)[:2]}")


@pytest.mark.timeout(300)
@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_notebook_runs(path, tmp_path, monkeypatch):
    monkeypatch.setenv("PBP_SHORT_RUN", "1")
    monkeypatch.setenv("PBP_TUTORIAL_OUTPUT", str(tmp_path / "outputs"))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    # Kernel "python3" runs `python`, which jupyter_client replaces by this interpreter (the
    # project's venv); the venv's bin first on PATH makes sure of it.
    bin_dir = str(pathlib.Path(sys.executable).parent)
    monkeypatch.setenv("PATH", bin_dir + os.pathsep + os.environ.get("PATH", ""))
    notebook = nbformat.read(path, as_version=4)
    notebook.cells.insert(0, nbformat.v4.new_code_cell(STRICT_WARNINGS))
    client = nbclient.NotebookClient(
        notebook, timeout=240, kernel_name="python3",
        resources={"metadata": {"path": str(TUTORIALS)}})
    client.execute()
