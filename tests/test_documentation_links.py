"""The documentation's links lead somewhere: every relative link of the README, of
`docs/` and of the tutorials' Markdown names a file of the repository, and none leaves it
(a reader of the checkout, or of the published repository, has nothing outside it)."""

import json
import pathlib
import re

import pytest

REPO = pathlib.Path(__file__).resolve().parents[1]
# [text](target) and ![alt](target); the target ends at whitespace or the closing bracket.
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")
PAGES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
NOTEBOOKS = sorted((REPO / "tutorials").glob("*.ipynb"))


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
    assert {path.name for path in PAGES} >= {"README.md", "design.md", "dmp.md"}


@pytest.mark.parametrize("path", PAGES + NOTEBOOKS, ids=lambda path: path.name)
def test_every_relative_link_names_a_file_of_the_repository(path):
    for target in _relative_links(_markdown(path)):
        resolved = (path.parent / target).resolve()
        assert resolved.is_relative_to(REPO), f"{path.name}: {target} leaves the repository"
        assert resolved.exists(), f"{path.name}: {target} does not exist"


def test_the_readme_and_the_dmp_tutorial_point_to_the_pages():
    assert "docs/dmp.md" in _relative_links((REPO / "README.md").read_text())
    assert "docs/design.md" in _relative_links((REPO / "README.md").read_text())
    tutorial = _markdown(REPO / "tutorials" / "01_dmp_basics.ipynb")
    assert "../docs/dmp.md" in _relative_links(tutorial)
