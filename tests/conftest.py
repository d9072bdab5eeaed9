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


def pytest_collection_modifyitems(items):
    """The files holding slow tests first, each file's tests in their order: in `make test`'s
    two processes the long tests start early and the short ones fill in at the end, so that
    neither process ends waiting on a long test the other could have shared (a file kept
    whole keeps its module fixtures made once)."""
    slow_files = {item.path for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: item.path not in slow_files)
