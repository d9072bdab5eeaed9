"""The documentation's links lead somewhere and its pages speak of the product.

Every relative link of the README, of the site's pages (`docs/**/*.md`, the build and the
generated results tables aside) and of the tutorials' Markdown names a file of the
repository, and none leaves it (a reader of the checkout, or of the published repository,
has nothing outside it); a link's `#anchor` names a heading of the page it leads to (MyST's
and GitHub's slug of the heading), and so does a scenario file's or a module's pointer to a
page's section (`(README, "A heading")`). The README stays short, and no file of the product
tells the story of its development (tracker numbers, what happened on which day)."""

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


FENCED = re.compile(r"^(```|~~~).*?^\1", re.M | re.S)
HEADING = re.compile(r"^(#{1,6})\s+(.+?)\s*#*\s*$", re.M)


def slug(title):
    """GitHub's (and MyST's `myst_heading_anchors`) anchor of a heading: its text (code
    without backticks, a link's text) lowercased, spaces to hyphens, and every character
    but word characters, hyphens and spaces dropped."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", title).replace("`", "")
    return re.sub(r"[^\w\- ]", "", text.lower().replace(" ", "-"))


def anchors(path):
    """The anchors of a page's headings (a repeated one gets -1, -2, ...)."""
    found = set()
    for _, title in HEADING.findall(FENCED.sub("", _markdown(path))):
        base = anchor = slug(title)
        number = 0
        while anchor in found:
            number += 1
            anchor = f"{base}-{number}"
        found.add(anchor)
    return found


def _anchored_links(text):
    """(page or "", anchor) of every link with an anchor, web addresses aside."""
    for target in LINK.findall(FENCED.sub("", text)):
        if "#" in target and not re.match(r"[a-z]+:", target):
            page, anchor = target.split("#", 1)
            yield page, anchor


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


@pytest.mark.parametrize("path", PAGES + NOTEBOOKS, ids=lambda path: str(path.relative_to(REPO)))
def test_every_anchor_names_a_heading_of_its_page(path):
    for page, anchor in _anchored_links(_markdown(path)):
        target = (path.parent / page).resolve() if page else path
        assert anchor in anchors(target), (
            f"{path.name}: {page}#{anchor} names no heading of {target.name} "
            f"(its anchors: {sorted(anchors(target))})")


def test_the_anchor_of_a_heading_is_githubs():
    # From the rule: lowercase, spaces to hyphens, punctuation dropped, code unquoted.
    assert slug("PBP on your own arm") == "pbp-on-your-own-arm"
    assert slug("The `pose` goal estimator") == "the-pose-goal-estimator"
    assert slug("Six-DoF PBP: blending poses, twists") == "six-dof-pbp-blending-poses-twists"


# A pointer to a page's section in a comment or docstring: `(README, "Heading")`,
# `README.md ("Heading")`, `docs/tasks/x.md, "Heading"`.
SECTION_POINTER = re.compile(r'(README(?:\.md)?|docs/[\w/.-]+\.md)(?:,\s*|\s+)\(?"([^"]+)"')


def _pointer_sources():
    yield from sorted((REPO / "diagrams").glob("*.yaml"))
    for package in ("pbp_drake", "pbp_drake_bench"):
        yield from sorted((REPO / package).rglob("*.py"))


@pytest.mark.parametrize("path", list(_pointer_sources()),
                         ids=lambda path: str(path.relative_to(REPO)))
def test_a_pointer_to_a_section_names_a_heading_that_exists(path):
    # Comments and docstrings wrap: read them as one line.
    text = re.sub(r"\s*\n\s*#*:?\s*", " ", path.read_text())
    for page, heading in SECTION_POINTER.findall(text):
        page = "README.md" if page.startswith("README") else page
        assert slug(heading) in anchors(REPO / page), (
            f"{path.relative_to(REPO)} points to {page} (\"{heading}\"), which has no such "
            "heading")


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
    yield from sorted((REPO / "pbp_drake_bench").rglob("*.py"))
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
