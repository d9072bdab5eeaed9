"""Large scenario files and files of aliases are refused in seconds and a bounded memory,
naming the file and the field, exit 2, nothing written: a file over 1 MiB by its size, a
file whose aliases repeat more than 100,000 values (a "billion laughs", merge keys, a cycle)
before any value is made, more than 100,000 goals or objects before they are read; a
`!!python` tag runs nothing. A file of 10,000 goals written at full precision still loads.

The in-process tests bound the time of `pbp-drake run FILE --headless`; the slow one runs
each refused file in a process of its own and bounds its memory."""

import dataclasses
import json
import pathlib
import subprocess
import sys
import types

import pytest
from pydrake.common.yaml import yaml_dump_typed, yaml_load_typed

from pbp_drake.core.reach_task import sample_grid_scene
from pbp_drake.scenarios import (
    ScenarioError, ScenarioFile, TaskScenarioFile, load_scenario_file, resolve)
from pbp_drake.scenarios.loading import file_schema
from pbp_drake.scenarios import bounds
from pbp_drake.scenarios.bounds import (
    MAX_GOALS, MOST_ALIASED_VALUES, MOST_FILE_BYTES, load_document, load_typed)

DIAGRAMS = pathlib.Path(__file__).resolve().parents[2] / "diagrams"
TOY = (DIAGRAMS / "toy_alt_vs_cont.yaml").read_text()
REACH = (DIAGRAMS / "hsr_reach.yaml").read_text()
TOY_GOALS = "goals: [[1.0, 0.0]]"


def _toy_goals(goals):
    assert TOY_GOALS in TOY
    return TOY.replace(TOY_GOALS, f"goals: {goals}")


# _reach_objects puts the objects on this line's place, so the loader names its number.
OBJECTS_ANCHOR = "    switch_schedule:"
OBJECTS_LINE = REACH[:REACH.index(OBJECTS_ANCHOR)].count("\n") + 1


def _reach_objects(objects):
    return REACH.replace(OBJECTS_ANCHOR,
                         f"    objects: {objects}\n    targets: [0, 1, 2]\n{OBJECTS_ANCHOR}")


def _laughs(levels=9, width=9):
    """A billion laughs in scenario.goals: each level a list of `width` aliases of the last."""
    items = ["&a0 [1.0, 0.0]"] + [f"&a{level} [" + ", ".join([f"*a{level - 1}"] * width) + "]"
                                  for level in range(1, levels + 1)]
    return _toy_goals("[" + ", ".join(items) + "]")


def _merge_keys(levels=9, width=9):
    """Merge keys (`<<`) nested as the laughs are, in scenario.dmp."""
    dmp = "  dmp: {formulation: ijspeert, basis_count: 50}"
    assert dmp in TOY
    lines = ["  dmp: &m0 {formulation: ijspeert, basis_count: 50}"] + [
        f"  _m{level}: &m{level} {{<<: [" + ", ".join([f"*m{level - 1}"] * width) + "]}"
        for level in range(1, levels + 1)]
    return TOY.replace(dmp, "\n".join(lines))


def _many_obstacles(count=20_000):
    """Some 100 KB: one obstacle written once and named `count` times."""
    obstacles = ", ".join(["*o"] * count)
    return _toy_goals("[[1.0, 0.0]]\n  _obstacle: &o {center: [0.5, 0.5], radius: 0.1}\n"
                      f"  obstacles: [{obstacles}]")


# name: (the file's text, words stderr must hold, seconds the refusal may take). The text
# is built when the test runs; the seconds leave room for a loaded machine (the same files
# took 82 s, over 120 s and 85 s before the bounds).
CASES = {
    # Ten megabytes of goals written at full precision.
    "ten_megabytes_of_goals": (lambda: _toy_goals(
        "[" + ", ".join(["[0.12345678901234567, -0.9876543210987654]"] * 250_000) + "]"),
        [f"{MOST_FILE_BYTES:,} bytes", "at most"], 5.0),
    "300,000_objects": (lambda: _reach_objects(
        "[" + ",".join(["[2.0,0.1,0.7]"] * 300_000) + "]"),
        [f"{MOST_FILE_BYTES:,} bytes"], 5.0),
    # Under 1 MiB, written tight: the count refuses them, before they are read.
    "objects_over_the_cap": (lambda: _reach_objects(
        "[" + ",".join(["[2,0,0.7]"] * (MAX_GOALS + 1)) + "]"),
        ["scenario.task.objects", f"line {OBJECTS_LINE}",
         f"more than {MAX_GOALS:,} objects"], 30.0),
    "goals_over_the_cap": (lambda: _toy_goals("[" + ",".join(["[1,0]"] * (MAX_GOALS + 1)) + "]"),
                           ["scenario.goals", "line 11", f"more than {MAX_GOALS:,} goals"],
                           30.0),
    "billion_laughs": (_laughs, ["scenario.goals[", "line 11", "aliases",
                                 f"{MOST_ALIASED_VALUES:,}"], 5.0),
    "merge_keys": (_merge_keys, ["scenario._m", "aliases", f"{MOST_ALIASED_VALUES:,}"], 5.0),
    "an_obstacle_named_20,000_times": (_many_obstacles, [
        "scenario.obstacles[", "aliases", f"{MOST_ALIASED_VALUES:,}"], 5.0),
    "alias_cycle": (lambda: _toy_goals("&g [[1.0, 0.0], *g]"),
                    ["scenario.goals[1], line 11", "*g", "cycle"], 5.0),
}


def _write(tmp_path, name):
    path = tmp_path / f"{name}.yaml"
    path.write_text(CASES[name][0]())
    return path


@pytest.mark.slow
@pytest.mark.parametrize("name", CASES)
def test_a_large_or_aliased_file_is_refused_in_seconds_naming_the_field(
        name, tmp_path, run_refused):
    path = _write(tmp_path, name)
    _, words, seconds = CASES[name]
    code, err, elapsed = run_refused(path)
    assert code == 2, err
    assert err.startswith(f"pbp-drake: {path}: "), err
    assert "Traceback" not in err
    for word in words:
        assert word in err, (word, err)
    assert elapsed < seconds, elapsed
    assert list(tmp_path.iterdir()) == [path]  # nothing written


def test_the_size_cap_reads_no_more_than_it_allows(tmp_path):
    at_cap = tmp_path / "at_cap.yaml"
    padding = MOST_FILE_BYTES - len(TOY.encode()) - 1
    at_cap.write_text(TOY + "#" * padding + "\n")
    assert at_cap.stat().st_size == MOST_FILE_BYTES
    load_scenario_file(at_cap)  # a comment of a megabyte: within the cap
    over = tmp_path / "over.yaml"
    over.write_text(TOY + "#" * (padding + 1) + "\n")
    with pytest.raises(ScenarioError, match=f"holds {MOST_FILE_BYTES + 1:,} bytes"):
        load_scenario_file(over)


@pytest.mark.parametrize("name", ["python_object_apply", "python_at_the_top"])
def test_a_python_tag_runs_nothing(name, tmp_path, run_refused, monkeypatch):
    monkeypatch.chdir(tmp_path)
    command = "!!python/object/apply:os.system ['touch ran']"
    text = _toy_goals(command) if name == "python_object_apply" else command + "\n"
    path = tmp_path / "tagged.yaml"
    path.write_text(text)
    code, err, elapsed = run_refused(path)
    assert code == 2 and "Traceback" not in err, err
    assert err.startswith(f"pbp-drake: {path}: line "), err
    assert not (tmp_path / "ran").exists()
    assert elapsed < 5.0


def test_a_scenario_built_in_python_is_held_to_the_goal_cap():
    scenario = load_scenario_file(DIAGRAMS / "toy_alt_vs_cont.yaml").scenario
    crowded = dataclasses.replace(scenario, goals=[[1.0, 0.0]] * (MAX_GOALS + 1))
    with pytest.raises(ScenarioError, match=f"scenario.goals holds {MAX_GOALS + 1:,} goals; "
                       f"a scenario has at most {MAX_GOALS:,}"):
        resolve(crowded)


@pytest.mark.slow
def test_ten_thousand_goals_at_full_precision_load_within_the_cap(tmp_path):
    file = load_scenario_file(DIAGRAMS / "hsr_reach.yaml")
    task = file.scenario.task
    scene, separation = sample_grid_scene(0, 10_000, task.x_range, task.y_range, task.height,
                                          task.switch_schedule)
    scenario = dataclasses.replace(file.scenario, task=dataclasses.replace(
        task, objects=scene.objects.tolist(), targets=list(scene.targets),
        min_separation=0.9 * separation))
    path = tmp_path / "ten_thousand.yaml"
    path.write_text(yaml_dump_typed(TaskScenarioFile(scenario=scenario, study=file.study)))
    assert path.stat().st_size < MOST_FILE_BYTES / 1.5  # room to spare
    loaded = load_scenario_file(path)
    assert loaded.scenario.task.objects == scenario.task.objects
    assert loaded.resolved.goals.shape == (10_000, 3)


@pytest.mark.parametrize("path", sorted(DIAGRAMS.glob("*.yaml")), ids=lambda p: p.name)
def test_the_c_loader_reads_every_shipped_file_as_drake_does(path, monkeypatch):
    text = path.read_text()
    schema = file_schema(load_document(text))
    assert (schema is ScenarioFile) == path.name.startswith("toy_")
    drake = yaml_dump_typed(yaml_load_typed(schema=schema, data=text))
    assert yaml_dump_typed(load_typed(schema, load_document(text))) == drake
    # A Drake without the typed loader's pieces: its own yaml_load_typed, the same file.
    monkeypatch.setattr(bounds, "drake_yaml", types.SimpleNamespace())
    assert yaml_dump_typed(load_typed(schema, load_document(text))) == drake


# The memory a refusal may take beyond the imports, and all told: a few hundred MB at most
# (the same files took 1.46 GB and 649 MB before the bounds).
MOST_MEGABYTES_GROWN = 200
MOST_MEGABYTES = 400
# The peak is this process's own (VmHWM, kB): ru_maxrss keeps the high-water mark of the
# process it was forked from across exec, and a test worker's is over a gigabyte.
MEASURE = """
import json, re, sys, time
from pbp_drake import cli

def peak():
    with open("/proc/self/status") as status:
        return int(re.search(r"VmHWM:\\s+(\\d+)", status.read()).group(1))

before = peak()
start = time.monotonic()
code = cli.main(["run", sys.argv[1], "--headless", "--no-meshcat"])
seconds = time.monotonic() - start
after = peak()
print(json.dumps({"code": code, "seconds": seconds, "megabytes": after / 1024,
                  "megabytes_grown": (after - before) / 1024}))
"""


@pytest.mark.slow
@pytest.mark.parametrize("name", CASES)
def test_a_refusal_takes_a_bounded_memory(name, tmp_path):
    path = _write(tmp_path, name)
    _, words, seconds = CASES[name]
    done = subprocess.run([sys.executable, "-c", MEASURE, str(path)], capture_output=True,
                          text=True, timeout=300, cwd=tmp_path)
    measured = json.loads(done.stdout.splitlines()[-1])
    assert measured["code"] == 2, done.stderr
    assert words[0] in done.stderr and "Traceback" not in done.stderr, done.stderr
    assert measured["seconds"] < seconds, measured
    assert measured["megabytes_grown"] < MOST_MEGABYTES_GROWN, measured
    assert measured["megabytes"] < MOST_MEGABYTES, measured
    assert list(tmp_path.iterdir()) == [path]
