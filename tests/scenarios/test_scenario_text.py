"""A scenario from YAML text with overlays (what `--scenario-text` and `--set` read), one
number for a range, 30 Hz control, and an arm's model file beside its scenario file."""

import pathlib
import re

import pytest
from pydrake.common.yaml import yaml_dump_typed

from pbp_drake.scenarios import (
    ScenarioError, ScenarioOverrides, load_scenario_file, load_scenario_text)

REPO = pathlib.Path(__file__).resolve().parents[2]
REACH = (REPO / "diagrams" / "hsr_reach.yaml").read_text()
TOY = (REPO / "diagrams" / "toy_alt_vs_cont.yaml").read_text()


def test_text_loads_as_the_file_does():
    from_text = load_scenario_text(REACH, "reach")
    from_file = load_scenario_file(REPO / "diagrams" / "hsr_reach.yaml")
    assert yaml_dump_typed(from_text.scenario) == yaml_dump_typed(from_file.scenario)
    assert (from_text.resolved.goals == from_file.resolved.goals).all()


def test_overlays_change_only_their_fields():
    loaded = load_scenario_text(REACH, "reach", overlays=[
        "scenario: {goal_estimator: {method: nearest}}", "scenario: {control_period: 0.02}"])
    shipped = load_scenario_text(REACH, "reach").scenario
    assert loaded.scenario.goal_estimator.method == "nearest"
    assert loaded.scenario.control_period == 0.02
    # The task's other fields and its robot's tag are kept.
    assert loaded.scenario.task == shipped.task
    assert yaml_dump_typed(loaded.scenario.robot) == yaml_dump_typed(shipped.robot)


def test_one_number_for_a_range_is_exactly_that_number():
    loaded = load_scenario_text(REACH, "reach", overlays=["scenario: {task: {object_count: 5}}"])
    assert loaded.scenario.task.object_count == [5, 5]
    assert len(loaded.resolved.goals) == 5


@pytest.mark.parametrize("overlay, words", [
    ("scenario: {task: {object_cont: 5}}", ["reach: scenario.task: unknown key",
                                             "did you mean 'object_count'"]),
    ("scenario: {control_period: fast}", ["reach: scenario.control_period: got 'fast'",
                                          "a number"]),
    ("scenario: {task: {switch_schedule: 0.0}}", ["scenario.task.switch_schedule", "a list"]),
    ("scenario: {seed: 1.5}", ["scenario.seed", "an integer"]),
    ("scenario: {robot: !Hsrr {}}", ["scenario.robot", "!Hsrr", "did you mean !Hsr?"]),
    ("scenario: [", ["reach: the override 'scenario: ['", "YAML syntax error"]),
])
def test_a_bad_overlay_names_its_field(overlay, words):
    with pytest.raises(ScenarioError) as error:
        load_scenario_text(REACH, "reach", overlays=[overlay])
    for word in words:
        assert word in str(error.value)


ARM = (REPO / "diagrams" / "arm_reach.yaml").read_text()


@pytest.mark.parametrize("text, overlay, words", [
    (REACH, "scenario: {robot: {station: {control_period: 0.05}}}",
     "scenario.robot.station.control_period is set by the task from scenario.control_period"),
    (REACH, "scenario: {robot: {station: {ee_height: 0.9}}}",
     "scenario.robot.station.ee_height is set by the task from scenario.task.height"),
    (ARM, "scenario: {robot: {control_period: 0.05}}",
     "scenario.robot.control_period is set by the task from scenario.control_period"),
])
def test_a_station_field_the_task_sets_is_refused_naming_its_home(text, overlay, words):
    """Given in the robot's section, the value would be overwritten by the task's unseen."""
    with pytest.raises(ScenarioError, match=words) as error:
        load_scenario_text(text, "scene", folder=REPO / "diagrams", overlays=[overlay])
    assert "\n" not in str(error.value)


def test_a_period_off_the_plant_step_says_the_values():
    with pytest.raises(ScenarioError) as error:
        load_scenario_text(REACH, "reach", overlays=["scenario: {control_period: 0.0333}"])
    message = str(error.value)
    assert "scenario.control_period 0.0333 s is 6.66 steps of" in message
    assert "plant.time_step 0.005 s" in message
    assert "0.03 s or 0.035 s" in message
    # 0.0333 s is ten steps of 0.00333 s (the diff IK's 0.03 s nine of them).
    assert "plant.time_step of 0.00333 s (10 steps)" in message


def test_30_hz_runs_at_ten_plant_steps_of_a_third_of_a_millisecond():
    loaded = load_scenario_text(REACH, "reach", overlays=[
        "scenario: {control_period: 0.0333, robot: !Hsr {station: {plant: {time_step: "
        "0.0033333}}}}"])
    resolved = loaded.resolved
    # Within 0.2 % of ten steps: the controller and the station tick at exactly ten.
    assert resolved.controller.control_period == pytest.approx(10 * 0.0033333, abs=1e-15)
    assert resolved.station.control_period == resolved.controller.control_period
    assert resolved.station.diff_ik_time_step == pytest.approx(9 * 0.0033333, abs=1e-15)
    # The toy robot's step too.
    toy = load_scenario_text(TOY, "toy", overlays=[
        "scenario: {control_period: 0.0333, robot: {time_step: 0.0033333}}"])
    assert toy.resolved.scenario.control_period == pytest.approx(10 * 0.0033333, abs=1e-15)


def test_a_shipped_period_is_kept_to_the_bit():
    loaded = load_scenario_text(REACH, "reach")
    assert loaded.resolved.controller.control_period == 0.03
    assert loaded.resolved.station.diff_ik_time_step == 0.03


def test_a_relative_model_file_is_read_beside_the_scenario_file(tmp_path, monkeypatch):
    folder = tmp_path / "robot"
    (folder / "urdf").mkdir(parents=True)
    (folder / "urdf" / "arm.urdf").write_text(
        (REPO / "models" / "pbp_drake_models" / "arm7" / "pbp_arm7.urdf").read_text())
    text = (REPO / "diagrams" / "arm_reach.yaml").read_text().replace(
        "package://pbp_drake_models/arm7/pbp_arm7.urdf", "urdf/arm.urdf")
    (folder / "arm.yaml").write_text(text)
    monkeypatch.chdir(tmp_path)  # not the scenario's folder
    loaded = load_scenario_file(folder / "arm.yaml")
    assert loaded.scenario.robot.model_file == str(folder / "urdf" / "arm.urdf")
    with pytest.raises(ScenarioError, match="model_file"):
        load_scenario_text(text, "text")  # from the working folder: no such file


def _primitives(tmp_path, copy):
    """A scenario `scene/wall.yaml`, the shipped wall primitive beside it in
    `scene/primitives/`, and in the working folder `tmp_path` a `primitives/` holding the
    same file (`copy`) or another one; the overrides that name it relatively."""
    shipped = REPO / "diagrams" / "primitives" / "around_the_wall.json"
    for folder in ("scene/primitives", "primitives"):
        (tmp_path / folder).mkdir(parents=True)
    (tmp_path / "scene" / "wall.yaml").write_text(
        (REPO / "diagrams" / "hsr_wall.yaml").read_text())
    (tmp_path / "scene" / "primitives" / "wall.json").write_bytes(shipped.read_bytes())
    (tmp_path / "primitives" / "wall.json").write_bytes(
        shipped.read_bytes() if copy else b'{"format": "pbp_drake.primitive"}')
    return ScenarioOverrides(settings=("dmp.primitive=primitives/wall.json",))


def test_a_typed_relative_primitive_naming_another_file_from_the_working_folder_is_refused(
        tmp_path, monkeypatch):
    # Read from the scenario's folder, the other primitive ran, exit 0.
    overrides = _primitives(tmp_path, copy=False)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ScenarioError, match=re.escape(
            "scenario.dmp.primitive primitives/wall.json is read from the scenario file's "
            f"folder, as {tmp_path}/scene/primitives/wall.json; the working folder has "
            "another primitives/wall.json: for that one, give ../primitives/wall.json or its "
            "absolute path; for the first, its absolute path")):
        load_scenario_file("scene/wall.yaml", overrides)
    # Not there at all: the refusal says where it looked and what to give.
    (tmp_path / "scene" / "primitives" / "wall.json").unlink()
    with pytest.raises(ScenarioError, match=re.escape(
            "scenario.dmp.primitive primitives/wall.json: a relative path is read from the "
            f"scenario file's folder, {tmp_path}/scene, which has no such file; for the "
            "working folder's, give ../primitives/wall.json or its absolute path")):
        load_scenario_file("scene/wall.yaml", overrides)


def test_a_relative_primitive_that_is_one_file_either_way_is_read(tmp_path, monkeypatch):
    overrides = _primitives(tmp_path, copy=True)
    monkeypatch.chdir(tmp_path)
    loaded = load_scenario_file("scene/wall.yaml", overrides)
    assert loaded.scenario.dmp.primitive == str(tmp_path / "scene/primitives/wall.json")
    # Written in the scenario file, a relative path names the file beside it alone.
    (tmp_path / "primitives" / "wall.json").write_text("another")
    text = (tmp_path / "scene" / "wall.yaml").read_text().replace(
        "basis_count: 50}", "basis_count: 50, primitive: primitives/wall.json}")
    (tmp_path / "scene" / "wall.yaml").write_text(text)
    assert load_scenario_file("scene/wall.yaml").resolved.controller.dmp_primitive
