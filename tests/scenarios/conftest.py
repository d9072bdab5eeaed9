import time

import pytest

from pbp_drake import cli
from pbp_drake.commands import run_page


@pytest.fixture
def run_refused(monkeypatch, capsys):
    """`run(path) -> (exit code, stderr, seconds)` of `pbp-drake run PATH --headless`, with
    Meshcat replaced by a failure: a file that is accepted fails the test instead of
    starting a simulation."""
    def no_simulation(*args, **kwargs):
        raise AssertionError("the file was accepted and a simulation started")

    monkeypatch.setattr(run_page, "Meshcat", no_simulation)

    def run(path):
        capsys.readouterr()
        start = time.monotonic()
        code = cli.main(["run", str(path), "--headless"])
        return code, capsys.readouterr().err, time.monotonic() - start

    return run
