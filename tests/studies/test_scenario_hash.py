"""A study folder resumes only the trials of its own scenario (`trial_files.scenario_hash`):
a field added to the schema later leaves the hash of a scenario whose trials it does not
change as it was, and changes the hash of one whose trials it does."""

import dataclasses
import pathlib

import numpy as np
import pytest

from pbp_drake.robots import ArmHardware, TaskSpaceBridgeConfig, ToolPose
from pbp_drake.scenarios import load_scenario_file
from pbp_drake.scenarios.overrides import ScenarioOverrides
from pbp_drake.studies.trial_files import content_differences, scenario_content, scenario_hash

DIAGRAMS = pathlib.Path(__file__).resolve().parents[2] / "diagrams"


def scenario(name):
    return load_scenario_file(DIAGRAMS / name).scenario


def with_reposition_time(scenario, seconds):
    operator = dataclasses.replace(scenario.operator, reposition_time=seconds)
    return dataclasses.replace(scenario, operator=operator)


def test_the_hsr_tasks_hash_without_reposition_time_at_its_default():
    # The HSR's base turns all the way round and its tasks are planar: the participant
    # never repositions there, so their study folders from before the field still resume.
    for name in ("hsr_reach.yaml", "hsr_obstacles.yaml"):
        hsr = scenario(name)
        assert "reposition_time" not in scenario_content(hsr)["operator"]
        assert scenario_hash(with_reposition_time(hsr, 2.0)) != scenario_hash(hsr)


def test_a_scenario_with_numpy_values_hashes_as_its_file_s():
    # A script may set a field from NumPy: the same values, the same study folder.
    hsr = scenario("hsr_reach.yaml")
    task = dataclasses.replace(hsr.task, switch_schedule=np.array(hsr.task.switch_schedule))
    numpy = dataclasses.replace(hsr, duration=np.float64(hsr.duration), task=task)
    assert scenario_hash(numpy) == scenario_hash(hsr)
    assert scenario_hash(dataclasses.replace(numpy, duration=np.float64(1.0))) != (
        scenario_hash(hsr))


def test_the_arm_task_hashes_reposition_time_even_at_its_default():
    # The arm's trials changed when the participant learned to reposition: its study
    # folders from before must be refused, not resumed with trials of the old participant.
    arm = scenario("arm_reach.yaml")
    assert scenario_content(arm)["operator"]["reposition_time"] == 4.0
    assert scenario_hash(with_reposition_time(arm, 2.0)) != scenario_hash(arm)


def test_a_renamed_station_field_keeps_the_name_folders_were_written_with():
    # `command_period` became `control_period`: the hash reads it under its old name.
    for name, section in (("hsr_reach.yaml", ("robot", "station")),
                          ("arm_reach.yaml", ("robot",))):
        content = scenario_content(scenario(name))
        for key in section:
            content = content[key]
        assert "command_period" in content and "control_period" not in content


@pytest.mark.parametrize("name, field, value", [("hsr_reach.yaml", "grid_objects", 100),
                                                ("hsr_grasp.yaml", "grasps_per_object", 30),
                                                ("hsr_obstacles.yaml", "obstacle_starts",
                                                 [[1.1, 0.0], [1.1, 0.3], [1.1, 0.6]])])
def test_a_later_task_field_changes_the_hash_and_its_default_leaves_it(name, field, value):
    # A grid of objects in the reaching task; many grasps an object in the grasping task.
    base = scenario(name)
    assert field not in scenario_content(base)["task"]
    changed = dataclasses.replace(base, task=dataclasses.replace(base.task, **{field: value}))
    assert scenario_content(changed)["task"][field] == value
    assert scenario_hash(changed) != scenario_hash(base)


def test_the_intent_filters_settings_at_their_defaults_leave_the_hash():
    reach = scenario("hsr_reach.yaml")
    assert "intent_filter" not in scenario_content(reach)["goal_estimator"]
    settings = dataclasses.replace(reach.goal_estimator.intent_filter, switch_rate=1.0)
    changed = dataclasses.replace(reach, goal_estimator=dataclasses.replace(
        reach.goal_estimator, intent_filter=settings))
    assert scenario_hash(changed) != scenario_hash(reach)



@pytest.mark.parametrize("name, field, value", [
    ("arm_reach.yaml", "singular_margin", 0.05),
    ("arm_reach.yaml", "limit_margin", 0.3),
    ("arm_reach.yaml", "ready_tool_pose", ToolPose(position=[0.3, 0.0, 0.4])),
    ("arm_reach.yaml", "hardware", ArmHardware(driver="iiwa")),
    ("hsr_reach.yaml", "hardware", TaskSpaceBridgeConfig(connect=True))])
def test_a_later_robot_field_changes_the_hash_and_its_default_leaves_it(name, field, value):
    # The arm's singular damping and limit margin, its ready pose as a tool pose, a real
    # robot's link.
    base = scenario(name)
    assert field not in scenario_content(base)["robot"]
    changed = dataclasses.replace(base, robot=dataclasses.replace(base.robot, **{field: value}))
    assert field in scenario_content(changed)["robot"]
    assert scenario_hash(changed) != scenario_hash(base)


def test_a_taught_primitive_is_hashed_by_its_content_not_its_path(tmp_path):
    base = scenario("hsr_reach.yaml")
    assert "primitive" not in scenario_content(base)["dmp"]

    def naming(path):
        return dataclasses.replace(base, dmp=dataclasses.replace(base.dmp, primitive=str(path)))

    first, copy, other = tmp_path / "a.json", tmp_path / "b.json", tmp_path / "c.json"
    first.write_text('{"format": "pbp_drake.primitive", "weights": [1]}')
    copy.write_text(first.read_text())
    other.write_text('{"format": "pbp_drake.primitive", "weights": [2]}')
    assert scenario_hash(naming(first)) == scenario_hash(naming(copy))
    assert scenario_hash(naming(first)) != scenario_hash(naming(other))
    assert scenario_hash(naming(first)) != scenario_hash(base)


def test_a_refused_folder_names_what_differs_from_its_scenario():
    hsr = scenario("hsr_reach.yaml")
    held = scenario_content(hsr)
    estimator = dataclasses.replace(hsr.goal_estimator, method="nearest")
    assert content_differences(held, scenario_content(dataclasses.replace(
        hsr, duration=12.5, goal_estimator=estimator))) == (
        '; duration 60.0 there, 12.5 here; goal_estimator.method "angle" there, "nearest" here')
    # Another operator is named by its tag, not field by field; a fourth difference is counted.
    keyboard = load_scenario_file(DIAGRAMS / "hsr_reach.yaml",
                                  ScenarioOverrides(["operator=!Keyboard {}"])).scenario
    assert content_differences(held, scenario_content(keyboard), most=0) == "; 1 more"
    assert content_differences(held, scenario_content(keyboard)) == (
        "; operator !VirtualParticipant there, !Keyboard here")
    assert content_differences(held, scenario_content(hsr)) == ""
    # A study.json from before the content was kept: nothing to compare, nothing said.
    assert content_differences(None, held) == ""
