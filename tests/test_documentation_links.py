"""The documentation's links lead somewhere and its pages speak of the product.

Every relative link of the README, of the site's pages (`docs/**/*.md`, the build and the
generated results tables aside) and of the tutorials' Markdown names a file of the
repository, and none leaves it (a reader of the checkout, or of the published repository,
has nothing outside it). The README stays short, and no file of the product tells the story
of its development (tracker numbers, what happened on which day)."""

import json
import pathlib
import re

import pytest

REPO = pathlib.Path(__file__).resolve().parents[1]
# [text](target) and ![alt](target); the target ends at whitespace or the closing bracket.
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")


def _site_pages():
    for path in sorted((REPO / "docs").rglob("*.md")):
        parts = path.relative_to(REPO / "docs").parts
        if "_build" not in parts and "generated" not in parts:
            yield path


PAGES = [REPO / "README.md", *_site_pages()]
NOTEBOOKS = sorted((REPO / "tutorials").glob("*.ipynb"))
README_MAX_LINES = 250


def _markdown(path):
    if path.suffix != ".ipynb":
        return path.read_text()
    cells = json.loads(path.read_text())["cells"]
    return "\n".join("".join(cell["source"]) for cell in cells
                     if cell["cell_type"] == "markdown")


def _relative_links(text):
    for target in LINK.findall(text):
        if not re.match(r"[a-z]+:|#", target):  # web addresses and anchors aside
            yield target.split("#")[0]


def test_the_design_and_dmp_pages_are_there():
    names = {str(path.relative_to(REPO)) for path in PAGES}
    assert names >= {"README.md", "docs/index.md", "docs/design.md", "docs/concepts/dmp.md",
                     "docs/getting-started.md"}


@pytest.mark.parametrize("path", PAGES + NOTEBOOKS, ids=lambda path: str(path.relative_to(REPO)))
def test_every_relative_link_names_a_file_of_the_repository(path):
    for target in _relative_links(_markdown(path)):
        resolved = (path.parent / target).resolve()
        assert resolved.is_relative_to(REPO), f"{path.name}: {target} leaves the repository"
        assert resolved.exists(), f"{path.name}: {target} does not exist"


def test_the_readme_and_the_dmp_tutorial_point_to_the_pages():
    readme = set(_relative_links((REPO / "README.md").read_text()))
    assert {"docs/concepts/dmp.md", "docs/design.md", "docs/getting-started.md"} <= readme
    tutorial = _markdown(REPO / "tutorials" / "01_dmp_basics.ipynb")
    assert "../docs/concepts/dmp.md" in _relative_links(tutorial)


def test_the_readme_is_short():
    lines = (REPO / "README.md").read_text().splitlines()
    assert len(lines) <= README_MAX_LINES, f"README.md has {len(lines)} lines"


# Phrases of a lab notebook, not of a product; built from pieces so that this file does not
# match them itself.
NOTEBOOK_PHRASES = re.compile("|".join([
    "iss" + r"ue [0-9]", "this " + "session", "earlier " + "today", "slow " + "stretch"]),
    re.IGNORECASE)


def _product_files():
    yield from (REPO / name for name in ("README.md", "CHANGELOG.md", "Makefile"))
    yield from (path for path in sorted((REPO / "docs").rglob("*.md"))
                if "_build" not in path.relative_to(REPO / "docs").parts)
    yield from NOTEBOOKS
    yield from sorted((REPO / "pbp_drake").rglob("*.py"))
    yield from sorted((REPO / "diagrams").glob("*.yaml"))
    yield from sorted((REPO / "tests").rglob("*.py"))


@pytest.mark.parametrize("path", [path for path in _product_files() if path.exists()],
                         ids=lambda path: str(path.relative_to(REPO)))
def test_no_file_of_the_product_reads_as_a_lab_notebook(path):
    for number, line in enumerate(path.read_text().splitlines(), start=1):
        found = NOTEBOOK_PHRASES.search(line)
        assert not found, f"{path.relative_to(REPO)}:{number}: {found.group(0)!r}"


def test_the_readme_quotes_the_generated_results_table():
    # The headline table is pasted from what `make results` wrote, never typed.
    readme = (REPO / "README.md").read_text()
    generated = (REPO / "docs" / "results" / "generated" / "hsr_reach_evaluation.md").read_text()
    section = readme.split("\n## Results\n", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("| ")]
    assert len(rows) >= 3 and all(row in generated.splitlines() for row in rows)
