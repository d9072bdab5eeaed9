import pathlib
import sys

import pytest
from pydrake.geometry import Meshcat, MeshcatParams

# The plain NumPy loop (the diagram's oracle) lives beside the builder tests.
sys.path.insert(0, str(pathlib.Path(__file__).parent / "builder"))


@pytest.fixture(scope="session")
def repo():
    return pathlib.Path(__file__).resolve().parents[1]


@pytest.fixture
def meshcat():
    """A Meshcat on a free local port (port 0), used only from the test's thread."""
    return Meshcat(MeshcatParams(host="localhost", port=0))
