import pathlib
import sys

import pytest

# Test helpers (the plain NumPy loop) live beside the tests.
sys.path.insert(0, str(pathlib.Path(__file__).parent))


@pytest.fixture(scope="session")
def repo():
    return pathlib.Path(__file__).resolve().parents[1]
