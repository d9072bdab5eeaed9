"""Broken scenario files end in `pbp-drake: FILE: ...` and exit 2 while loading, never in a
traceback, and at once."""

import itertools
import math
import os
import pathlib
import random

import pytest
from pydrake.common.yaml import yaml_dump, yaml_load

from pbp_drake.scenarios import ScenarioError, load_scenario_file
from pbp_drake.scenarios.bounds import check_yaml_bounds, load_document

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
    "scalar_for_list_hsr": (("hsr_reach.yaml",), _replace("switch_schedule: [0.0, 0.3, 0.6]",
                                                          "switch_schedule: 0.0"),
                            ["switch_schedule"]),
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
    "latin1": (SHIPPED, lambda text: text.replace("\n  method:", "\n  # café\n  method:", 1)
               .encode("latin-1"), ["byte", "is not UTF-8", "expected UTF-8 text"]),
    "control_character": (SHIPPED, _replace("\n  method:", "\n  # \a\n  method:"),
                          ["YAML error", "control characters are not allowed"]),
    "undefined_alias": (SHIPPED, _replace("control_period: 0.0", "control_period: *period #"),
                        ["line", "found undefined alias"]),
    "list_as_key": (SHIPPED, _replace("\n  method:", "\n  ? [a]\n  : 1\n  method:"),
                    ["line", "found unhashable key"]),
    # Was blamed on scenario.start and scenario.goals, the 2-D scene's defaults.
    "no_scenario_section": (("hsr_reach.yaml",), lambda text: "study:" + text.split("\nstudy:")[1],
                            ["has no `scenario:` section"]),
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


def _set(path, value):
    """A change that sets the value at `path` (keys and list indices) of the parsed file."""
    def change(text):
        data = yaml_load(data=text, private=True)
        node = data
        for key in path[:-1]:
            node = node[key]
        assert path[-1] in node if isinstance(node, dict) else path[-1] < len(node), path
        node[path[-1]] = value
        return yaml_dump(data)
    return change


def _leaves(node, path=()):
    """(path, value) of every value in a parsed file that is not a mapping."""
    if isinstance(node, dict):
        for key, value in node.items():
            if key != "_tag":
                yield from _leaves(value, path + (key,))
    else:
        yield path, node
        if isinstance(node, list):
            for index, item in enumerate(node):
                yield from _leaves(item, path + (index,))


def _field(path):
    return [key for key in path if isinstance(key, str)][-1]


ALL = ("hsr_reach.yaml", "hsr_obstacles.yaml", "toy_alpha_study.yaml", "toy_alt_vs_cont.yaml")
HSR = ALL[:2]
TWO = ("hsr_reach.yaml", "toy_alpha_study.yaml")
S, R, T = ("scenario",), ("scenario", "robot"), ("scenario", "task")
# (file names, change, words stderr must contain): the kinds of broken file, each
# on the files it applies to...
NAMED = [
    (TWO, _replace("\nscenario:", "\nscenario: [\n"), ["line"]),
    (TWO, _replace("\nscenario:\n", "\nscenario:\n name: x\n"), ["line"]),
    (TWO, _replace("\nstudy:", "\nstudy"), ["line"]),
    (TWO, _replace("\n  method:", "\n  \tmethod:"), ["line", "tab"]),
    (TWO, lambda text: "scenario:\n", ["scenario"]),
    (TWO, lambda text: "", ["empty", "scenario"]),
    (TWO, lambda text: "- scenario\n", ["top level", "a list"]),
    (TWO, _binary, ["binary"]),
    (TWO, lambda text: text.encode("utf-16"), ["UTF-8"]),
    (TWO, lambda text: text.encode("utf-16-le"), ["UTF-8"]),
    (TWO, _replace("\n  method:", "\n  method: teleop\n  method:"), ["duplicate", "method"]),
    (ALL, _set(S + ("control_period",), 0.0), ["control_period"]),
    (ALL, _set(S + ("control_period",), -0.01), ["control_period"]),
    (ALL, _set(S + ("dmp", "basis_count"), 100_000_000), ["basis_count"]),
    (ALL, _set(S + ("dmp", "basis_count"), -1), ["basis_count"]),
    (HSR, _set(R + ("speed",), math.inf), ["speed"]),
    (HSR, _set(R + ("station", "plant", "time_step"), 0.0), ["time_step"]),
    (HSR, _set(R + ("station", "plant", "time_step"), -0.005), ["time_step"]),
    (HSR, _set(S + ("seed",), -1), ["seed"]),
    (HSR, _set(("study", "tuning_seed"), -1), ["tuning_seed"]),
    (HSR, _set(T + ("x_range",), [2.5, 1.25]), ["x_range", "reversed"]),
    (HSR, _set(T + ("y_range",), [1.05, -1.05]), ["y_range", "reversed"]),
    (HSR, _set(S + ("duration",), math.inf), ["duration"]),
    (("hsr_reach.yaml",), _set(T + ("object_count",), [4, 2]), ["object_count", "reversed"]),
    (("hsr_obstacles.yaml",), _set(T + ("activation_range",), [0.5, 0.05]),
     ["activation_range", "reversed"]),
    (("hsr_obstacles.yaml",), _set(T + ("obstacle_radius",), math.inf), ["obstacle_radius"]),
    (ALL[2:], _set(R + ("time_step",), 0.0), ["time_step"]),
    (ALL[2:], _set(R + ("time_step",), -0.001), ["time_step"]),
    (ALL[2:], _set(R + ("mass",), 0.0), ["mass"]),
    (ALL[2:], _set(R + ("mass",), -1.0), ["mass"]),
    (ALL[2:], _set(R + ("damping",), -40.0), ["damping"]),
    (ALL[2:], _set(R + ("stiffness",), math.inf), ["stiffness"]),
    (("toy_alpha_study.yaml",), _set(S + ("obstacles", 0, "radius"), math.inf), ["radius"]),
    (("toy_alpha_study.yaml",), _set(("study", "scenes", 0, "obstacles", 0, "radius"),
                                     math.inf), ["radius"]),
    (("toy_alt_vs_cont.yaml",), _set(S + ("goals",), 1.0), ["goals"]),
    (("toy_alt_vs_cont.yaml",), _set(S + ("start",), 0.0), ["start"]),
]


def _generated():
    """...then every number of every shipped file replaced in turn by NaN, +inf, -inf or
    a word, and every list but a range (which takes one number) by a number."""
    junk = itertools.cycle([math.nan, math.inf, -math.inf, "fast"])
    for file in ALL:
        for path, value in _leaves(yaml_load(filename=str(DIAGRAMS / file), private=True)):
            if isinstance(value, list):
                if not _field(path).endswith("_range") and _field(path) != "object_count":
                    yield file, _set(path, 1.0), [_field(path)]
            elif type(value) in (int, float):
                yield file, _set(path, next(junk)), [_field(path)]


BROKEN = [(file, change, words) for files, change, words in NAMED for file in files]
GENERATED = list(_generated())
# Spread evenly over the files and their fields.
BROKEN += GENERATED[::len(GENERATED) // (100 - len(BROKEN))][:100 - len(BROKEN)]


@pytest.mark.slow
def test_a_hundred_broken_files_exit_2_naming_the_field(tmp_path, run_refused):
    """Each exits 2 within 10 s, with `pbp-drake: PATH: ` and
    the field (or the line) named, and no traceback."""
    assert len(BROKEN) == 100
    for index, (file, change, words) in enumerate(BROKEN):
        changed = change((DIAGRAMS / file).read_text())
        path = tmp_path / f"{index:03d}_{file}"
        if isinstance(changed, bytes):
            path.write_bytes(changed)
        else:
            path.write_text(changed)
        code, err, elapsed = run_refused(path)
        assert code == 2, (index, err)
        assert err.startswith(f"pbp-drake: {path}: "), (index, err)
        assert "Traceback" not in err, (index, err)
        for word in words:
            assert word.lower() in err.lower(), (index, word, err)
        assert elapsed < 10.0, (index, elapsed)


def test_a_missing_file_is_named(tmp_path, run_refused):
    path = tmp_path / "missing.yaml"
    code, err, _ = run_refused(path)
    assert code == 2 and err == f"pbp-drake: {path}: no such scenario file\n", err


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes")
def test_a_pipe_or_a_device_is_named_as_such_not_missing(tmp_path, run_refused):
    pipe = tmp_path / "scenario.yaml"
    os.mkfifo(pipe)
    for path in (pipe, pathlib.Path(os.devnull)):
        code, err, _ = run_refused(path)  # was "no such scenario file"
        assert code == 2 and err == (f"pbp-drake: {path}: is not a regular file (a device or "
                                     "a pipe); expected a scenario file such as "
                                     "diagrams/hsr_reach.yaml\n"), err


@pytest.mark.parametrize("make, message", [
    (lambda folder: folder, "{path}: is a folder; expected a scenario file"),
    (lambda folder: "", "the scenario file's path is empty"),
])
def test_a_folder_or_an_empty_path_is_named(tmp_path, make, message):
    path = make(tmp_path)
    with pytest.raises(ScenarioError, match=f"^{message.format(path=path)}"):
        load_scenario_file(path)  # both were "no such scenario file"


@pytest.mark.parametrize("path", [None, 3, b"diagrams/hsr_reach.yaml"])
def test_a_path_of_another_type_is_named(path):
    with pytest.raises(TypeError, match="path must be a scenario file's path, a str or "
                                        f"os.PathLike; got {path!r}"):
        load_scenario_file(path)


@pytest.mark.parametrize("overrides", [["duration=2.0"], "duration=2.0", {"duration": 2.0}])
def test_overrides_of_another_type_are_named(overrides):
    # A list, as --set is typed, failed in AttributeError: 'list' object has no 'words'.
    with pytest.raises(TypeError, match=r"^overrides must be a pbp_drake\.ScenarioOverrides "
                                        r"\(e\.g\. ScenarioOverrides\(settings="
                                        r"\('duration=2.0',\)\), as --set\) or None; got "):
        load_scenario_file(DIAGRAMS / SHIPPED[0], overrides)


def test_the_shipped_files_still_load():
    for file in SHIPPED:
        load_scenario_file(DIAGRAMS / file)


def test_duplicate_keys_are_per_mapping():
    load_document("a:\n  x: 1\nb:\n  x: 2\nc:\n  - x: 1\n    y: 2\n  - x: 3\n"
                         "d: {x: 1, y: {x: 2}}\ne: [{x: 1}, {x: 2}]\n"
                         "f: |\n  x: 1\n  x: 2\ng: 'x: 1, x: 2'\n")
    for text, line in (("a: 1\nb:\n  c: 1\na: 2\n", 4), ("a:\n  - x: 1\n    x: 2\n", 3),
                       ("a: {x: 1,\n    x: 2}\n", 2)):
        with pytest.raises(ScenarioError, match=f"line {line}: duplicate key"):
            load_document(text)


def test_a_scalar_anchor_and_a_merge_key_read_as_yaml_has_them():
    text = "a: &x 1.5\nb: *x\nc: {<<: {d: 2, e: 3}, e: 4}\n"
    check_yaml_bounds(text)  # one value repeated, far within the bound
    assert load_document(text) == {"a": 1.5, "b": 1.5, "c": {"d": 2, "e": 4}}
