"""`make test`'s runner (tests/run_suite.py): both runs happen, the browser tests' report
follows the others', and the exit code says whether any test failed."""

import pathlib
import subprocess
import sys

import pytest

RUNNER = pathlib.Path(__file__).with_name("run_suite.py")
INI = """[pytest]
markers = browser: drives a page
"""
BROWSER = """import pytest
pytestmark = pytest.mark.browser
def test_a_page():
    pass
"""


def _run(folder):
    return subprocess.run([sys.executable, str(RUNNER), "-q"],
                          cwd=folder, capture_output=True, text=True, timeout=300)


@pytest.mark.slow
def test_both_runs_report_and_a_failure_fails(tmp_path):
    (tmp_path / "pytest.ini").write_text(INI)
    (tmp_path / "test_page.py").write_text(BROWSER)
    (tmp_path / "test_other.py").write_text("def test_other():\n    assert False\n")
    failed = _run(tmp_path)
    others, _, browser = failed.stdout.partition("The browser tests, run alongside")
    assert failed.returncode == 1, failed.stdout + failed.stderr
    assert "1 failed" in others and "1 passed" in browser, failed.stdout

    (tmp_path / "test_other.py").unlink()  # the other run finds nothing: not a failure
    alone = _run(tmp_path)
    assert alone.returncode == 0 and "1 passed" in alone.stdout, alone.stdout + alone.stderr
