import gc
import pathlib
import sys
import threading

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


_start_thread = threading.Thread.start


def _start_after_collecting(thread):
    """Drake ends the process when a Meshcat is destroyed on another thread than the one that
    made it, and Python's cycle collector runs on whichever thread happens to allocate: a
    Meshcat that an earlier test left in a reference cycle (a LeafSystem holding it, owned by
    a diagram) could be destroyed on a page's reader thread. So the garbage is collected here,
    on the tests' thread, before any other thread starts."""
    if threading.current_thread() is threading.main_thread():
        gc.collect()
    _start_thread(thread)


threading.Thread.start = _start_after_collecting


def pytest_collection_modifyitems(items):
    """The files holding slow tests first, each file's tests in their order: in `make test`'s
    two processes the long tests start early and the short ones fill in at the end, so that
    neither process ends waiting on a long test the other could have shared (a file kept
    whole keeps its module fixtures made once)."""
    slow_files = {item.path for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: item.path not in slow_files)
