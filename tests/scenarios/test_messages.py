"""Messages that once named the wrong thing, through `pbp-drake run`: each
names the field and says what is wrong and what is expected."""

import pathlib
import re

import pytest

DIAGRAMS = pathlib.Path(__file__).resolve().parents[2] / "diagrams"


def _broken(tmp_path, file, old, new):
    text = (DIAGRAMS / file).read_text()
    assert old in text, old
    path = tmp_path / file
    path.write_text(text.replace(old, new, 1))
    return path


def _message(run_refused, path):
    code, err, _ = run_refused(path)
    assert code == 2, err
    prefix = f"pbp-drake: {path}: "
    assert err.startswith(prefix), err
    return err[len(prefix):].strip()


@pytest.mark.parametrize("file, old, new, mapping, real_keys, close", [
    # In the DMP settings, beta is close to a real key...
    ("toy_alt_vs_cont.yaml", "basis_count: 50}", "basis_count: 50, beta: 3}", "scenario.dmp",
     ["alpha_z", "basis_count", "beta_z"], "beta_z"),
    # ...in the task it is close to none: no suggestion, but the task's keys.
    ("hsr_reach.yaml", "    object_count: [2, 4]", "    object_count: [2, 4]\n    beta: 1",
     "scenario.task", ["object_count", "x_range", "switch_schedule"], None),
    ("hsr_obstacles.yaml", "    obstacle_count: 3", "    obstacle_count: 3\n    beta: 1",
     "scenario.task", ["obstacle_count", "activation_range"], None),
])
def test_an_unknown_key_names_its_mapping_and_the_real_keys(tmp_path, run_refused, file, old,
                                                            new, mapping, real_keys, close):
    message = _message(run_refused, _broken(tmp_path, file, old, new))
    assert message.startswith(f"{mapping}: unknown key 'beta'"), message
    assert "did you mean 'beta'" not in message
    for key in real_keys:
        assert key in message, (key, message)
    suggested = re.findall(r"did you mean '(\w+)'", message)
    assert suggested == ([close] if close else []), message


@pytest.mark.parametrize("file, old, field", [
    ("hsr_reach.yaml", "  seed: 0\nstudy", "scenario.seed"),
    ("hsr_obstacles.yaml", "  seed: 0\nstudy", "scenario.seed"),
    # The study's trials draw seeds tuning_seed, tuning_seed + 1, ...: the first would be -1.
    ("hsr_reach.yaml", "  tuning_seed: 0", "study.tuning_seed"),
])
def test_a_negative_seed_names_the_seed(tmp_path, run_refused, file, old, field):
    message = _message(run_refused, _broken(tmp_path, file, old, old.replace("seed: 0",
                                                                             "seed: -1")))
    assert message == (f"{field} -1 cannot seed the random draws; expected a non-negative "
                       "integer"), message


@pytest.mark.parametrize("file", ["hsr_reach.yaml", "hsr_obstacles.yaml"])
def test_a_reversed_range_says_it_is_reversed(tmp_path, run_refused, file):
    message = _message(run_refused, _broken(tmp_path, file, "x_range: [1.25, 2.5]",
                                            "x_range: [2.5, 1.25]"))
    assert message == ("scenario.task.x_range [2.5, 1.25] is reversed; expected [low, high] "
                       "with low <= high"), message


@pytest.mark.parametrize("file", ["hsr_reach.yaml", "hsr_obstacles.yaml"])
def test_an_endless_hsr_task_names_the_duration(tmp_path, run_refused, file):
    message = _message(run_refused, _broken(tmp_path, file, "duration: 60.0",
                                            "duration: .inf"))
    assert message.startswith("scenario.duration: inf is infinite; expected a finite"), message


@pytest.mark.parametrize("file, old, new, message", [
    # Drake's loader put the 3 into the first variant and failed later with a TypeError...
    ("toy_alpha_study.yaml", "  demonstration: !BentPath {start: [0.0, 0.0], goal: [1.0, 0.0], "
     "bend: 0.3, duration: 1.0}", "  demonstration: 3",
     "scenario.demonstration: got 3; expected a mapping, tagged with one of !BentPath, "
     "!RecordedPath (untagged: BentPath)"),
    # ...or ran the scenario on a default robot, the value silently dropped...
    ("toy_alpha_study.yaml", "  robot: {mass: 1.0, stiffness: 400.0, damping: 40.0, "
     "time_step: 0.01}", "  robot: 3",
     "scenario.robot: got 3; expected a mapping of the fields of PointRobot"),
    # ...or complained about an empty study.scenes.
    ("toy_alt_vs_cont.yaml", "study: !AltVsCont\n  goal_tolerance: 0.01", "study: fast",
     "study: got 'fast'; expected a mapping, tagged with one of !AlphaStudy, !AltVsCont, "
     "!MethodComparison (untagged: AlphaStudy)"),
])
def test_a_value_where_a_section_belongs_says_what_belongs(tmp_path, run_refused, file, old,
                                                          new, message):
    assert _message(run_refused, _broken(tmp_path, file, old, new)) == message


@pytest.mark.parametrize("old, new, message", [
    ("evaluation_seed: 10000", "evaluation_seed: 0",
     "study.evaluation_seed 0 is not above study.tuning_seed 0; expected the evaluation "
     "seeds after the tuning seeds"),
    ("split: evaluation", "split: test",
     "study.split 'test' is unknown; expected one of tuning, evaluation"),
])
def test_the_study_splits_are_checked(tmp_path, run_refused, old, new, message):
    assert _message(run_refused, _broken(tmp_path, "hsr_reach.yaml", old, new)) == message


@pytest.mark.parametrize("old, new, message", [
    ("stall_time: 4.0", "stall_time: 0.0",
     "scenario.operator.stall_time must be finite and positive, got 0.0"),
    ("plan_directions: 24", "plan_directions: 2.5",
     "scenario.operator.plan_directions: got 2.5; expected an integer"),
    ("plan_times: [0.1, 0.3, 0.6, 1.0, 1.5]", "plan_times: [1.5, 1.0]",
     "scenario.operator.plan_times [1.5, 1.0] must be 1 to 100 positive times (s) that "
     "increase strictly, e.g. [0.1, 0.3, 0.6, 1.0, 1.5]"),
])
def test_a_bad_participant_field_is_named(tmp_path, run_refused, old, new, message):
    assert _message(run_refused, _broken(tmp_path, "hsr_obstacles.yaml", old, new)) == message


def test_a_misspelt_participant_field_is_suggested(tmp_path, run_refused):
    message = _message(run_refused, _broken(tmp_path, "hsr_obstacles.yaml", "stall_time: 4.0",
                                            "stall_tme: 4.0"))
    assert message.startswith("scenario.operator: unknown key 'stall_tme' (did you mean "
                              "'stall_time'?)"), message
