"""The documentation site builds as `make docs` builds it, with no warning, and its generated
reference pages hold what a reader looks for; every field of a scenario file has a
description (the scenario-files page prints it). That every public name imports is
tests/test_public_api.py's."""

import dataclasses
import pathlib
import subprocess
import sys

import pytest

import pbp_drake
from pbp_drake.cli_types import EXIT_CODES

REPO = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "docs" / "_ext"))
import pbp_docs  # noqa: E402  (docs/_ext is not a package)


@pytest.mark.slow
def test_every_scenario_field_has_a_description():
    from pbp_drake.scenarios.schema import ScenarioFile, TaskScenario

    missing = [f"{cls.__name__}.{field.name}"
               for cls in pbp_docs.reachable_dataclasses(ScenarioFile, TaskScenario)
               for field in dataclasses.fields(cls)
               if not pbp_docs.field_docs(cls).get(field.name)]
    assert not missing, f"fields without a #: doc comment: {missing}"


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("html")
    build = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html",
                            "docs", str(out)], cwd=REPO, capture_output=True, text=True)
    return build, out


def _page(out, name):
    import html
    import re
    text = (out / "reference" / f"{name}.html").read_text()
    return html.unescape(re.sub(r"<[^>]+>", "", text))  # the text a reader sees


@pytest.mark.slow
def test_the_site_builds_without_warnings(site):
    build, _ = site
    log = build.stdout + build.stderr
    assert build.returncode == 0, log
    assert "WARNING" not in log and "ERROR" not in log, log


@pytest.mark.slow
def test_the_reference_pages_hold_what_a_reader_looks_for(site):
    _, out = site
    cli = _page(out, "cli")
    for command in ["run", "study", "report", "compare", "bench", "draw"]:
        assert f"pbp-drake {command}" in cli
    assert "--wait-for-browser" in cli and "--depth" in cli and "--quick" in cli
    # The exit codes, each with its meaning (a script reads them).
    assert "Exit codes" in cli
    for code, meaning in EXIT_CODES.items():
        assert f"{code}{meaning.replace('`', '')[:20]}" in cli, code
    scenario = _page(out, "scenario-files")
    assert "reaction_delay" in scenario and "default 0.5" in scenario
    assert "!Hsr" in scenario
    # The API page is a table a person scans: every name, linked to its own page, which
    # holds the docstrings (a system's port diagram among them).
    api = _page(out, "api")
    html = (out / "reference" / "api.html").read_text()
    for name in pbp_drake.__all__:
        if name != "__version__":
            assert name in api and f'href="api/{name}.html"' in html, name
            assert (out / "reference" / "api" / f"{name}.html").exists(), name
    assert "robot_state ──▶" not in api
    assert "robot_state ──▶" in _page(out, "api/Blender")
    assert len(api.split()) < 4000, "the API page holds more than its table"
