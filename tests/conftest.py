import pathlib
import sys

import pytest
from pydrake.geometry import Meshcat, MeshcatParams

# Test helpers (the plain NumPy loop) live beside the tests.
sys.path.insert(0, str(pathlib.Path(__file__).parent))


@pytest.fixture(scope="session")
def repo():
    return pathlib.Path(__file__).resolve().parents[1]


@pytest.fixture
def meshcat():
    """A Meshcat on a free local port (port 0), used only from the test's thread."""
    return Meshcat(MeshcatParams(host="localhost", port=0))
