"""Broken scenario files end in `pbp-drake: FILE: ...` and exit 2 while loading, never in a
traceback, and at once (issue 13)."""

import pathlib
import random

import pytest

from pbp_drake.scenarios import ScenarioError, load_scenario_file
from pbp_drake.scenarios.yaml_checks import check_duplicate_keys

DIAGRAMS = pathlib.Path(__file__).resolve().parents[2] / "diagrams"
SHIPPED = ("hsr_reach.yaml", "toy_alt_vs_cont.yaml")


def _replace(old, new):
    def change(text):
        assert old in text, old
        return text.replace(old, new, 1)
    return change


def _binary(_text):
    rng = random.Random(0)
    return bytes(rng.randrange(256) for _ in range(512)) + b"\0\0\0"


# name: (file names it applies to, change of the text, words stderr must contain)
VARIANTS = {
    "string_for_number": (SHIPPED, _replace("control_period: 0.0", "control_period: fast #"),
                          ["control_period"]),
    "nan_number": (SHIPPED, _replace("control_period: 0.0", "control_period: .nan #"),
                   ["control_period"]),
    "scalar_for_list": (("toy_alt_vs_cont.yaml",), _replace("goals: [[1.0, 0.0]]",
                                                            "goals: 1.0"), ["goals"]),
    "scalar_for_list_hsr": (("hsr_reach.yaml",), _replace("x_range: [1.25, 2.5]",
                                                          "x_range: 1.25"), ["x_range"]),
    "unclosed_bracket": (SHIPPED, _replace("dmp: {formulation: ijspeert, basis_count: 50}",
                                           "dmp: {formulation: ijspeert, basis_count: [50}"),
                         ["line"]),
    "tab_indent": (SHIPPED, _replace("\n  method:", "\n\tmethod:"), ["line", "tab"]),
    "empty_scenario": (SHIPPED, lambda text: "scenario:\n", ["scenario"]),
    "binary": (SHIPPED, _binary, ["binary"]),
    "utf16": (SHIPPED, lambda text: text.encode("utf-16"), ["UTF-8"]),
    "duplicate_key": (SHIPPED, _replace("\n  method:", "\n  control_period: 0.05\n  method:"),
                      ["duplicate", "control_period", "line"]),
    "duplicate_flow_key": (SHIPPED, _replace("basis_count: 50}", "basis_count: 50, "
                                             "basis_count: 60}"),
                           ["duplicate", "basis_count", "line"]),
    "huge_basis_count": (SHIPPED, _replace("basis_count: 50", "basis_count: 100000000"),
                         ["basis_count", "10000"]),
}
CASES = [(name, file) for name, (files, _, _) in VARIANTS.items() for file in files]


@pytest.mark.parametrize("name, file", CASES, ids=[f"{n}-{f[:-5]}" for n, f in CASES])
def test_a_broken_file_is_refused_while_loading(name, file, tmp_path, run_refused):
    _, change, words = VARIANTS[name]
    changed = change((DIAGRAMS / file).read_text())
    path = tmp_path / file
    if isinstance(changed, bytes):
        path.write_bytes(changed)
    else:
        path.write_text(changed)
    code, err, elapsed = run_refused(path)
    assert code == 2, err
    assert err.startswith(f"pbp-drake: {path}: "), err
    assert "Traceback" not in err
    for word in words:
        assert word.lower() in err.lower(), (word, err)
    assert elapsed < 5.0, elapsed


def test_the_shipped_files_still_load():
    for file in SHIPPED:
        load_scenario_file(DIAGRAMS / file)


def test_duplicate_keys_are_per_mapping():
    check_duplicate_keys("a:\n  x: 1\nb:\n  x: 2\nc:\n  - x: 1\n    y: 2\n  - x: 3\n"
                         "d: {x: 1, y: {x: 2}}\ne: [{x: 1}, {x: 2}]\n"
                         "f: |\n  x: 1\n  x: 2\ng: 'x: 1, x: 2'\n")
    for text, line in (("a: 1\nb:\n  c: 1\na: 2\n", 4), ("a:\n  - x: 1\n    x: 2\n", 3),
                       ("a: {x: 1,\n    x: 2}\n", 2)):
        with pytest.raises(ScenarioError, match=f"line {line}: duplicate key"):
            check_duplicate_keys(text)
