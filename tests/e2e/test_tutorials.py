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
            "04_build_your_own_diagram", "05_run_a_study", "06_hsr_station"]

# Run first in every notebook's kernel.
STRICT_WARNINGS = """\
import warnings
from pydrake.common.deprecation import DrakeDeprecationWarning

warnings.simplefilter("error", DrakeDeprecationWarning)
"""


def test_all_six_tutorials_are_there():
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
