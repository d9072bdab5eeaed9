"""Values the random mutations (test_random_mutations.py) found getting past the checks
into a division, a norm or a simulation: each now refused, naming its field; and the checks
no other test reached, each with a value it refuses."""

import dataclasses
import math
import os
import pathlib
import re

import numpy as np
import pytest

from pbp_drake.scenarios import (
    MethodComparison, MultiGoalReach, ScenarioError, ScriptedCommands, check_method_comparison,
    load_scenario_file, resolve, task_scene)
from pbp_drake.scenarios.resolution import MAX_PRIMITIVE_BYTES, load_primitive

DIAGRAMS = pathlib.Path(__file__).resolve().parents[2] / "diagrams"


@pytest.mark.parametrize("file, old, new, message", [
    # Divided by before the station was checked: ZeroDivisionError, or NaN to an integer.
    ("hsr_reach.yaml", "time_step: 0.005", "time_step: 0.0",
     r"scenario.robot.station.plant.time_step 0 s is too short; expected at least 1e-06 s"),
    ("hsr_reach.yaml", "time_step: 0.005", "time_step: .nan",
     r"scenario.robot.station.plant.time_step: NaN"),
    ("hsr_obstacles.yaml", "diff_ik_time_step: 0.01", "diff_ik_time_step: .inf",
     r"scenario.robot.station.diff_ik_time_step: inf is infinite"),
    # Passed "positive", then a second of simulation never ended.
    ("toy_alt_vs_cont.yaml", "time_step: 0.001", "time_step: 1.0e-300",
     r"scenario.robot.time_step 1e-300 s is too short"),
    # A DMP lasting 1e300 s (overflow in its gains) or 1e-300 s (division by zero).
    ("hsr_reach.yaml", "speed: 0.12", "speed: 1.0e-300",
     r"scenario.robot.speed gives the DMPs a duration of .* expected 0.03 s"),
    ("toy_alt_vs_cont.yaml", "dmp_duration: 1.0", "dmp_duration: 1.0e-300",
     r"scenario.dmp_duration gives the DMPs a duration of 1e-300 s; expected 0.01 s"),
    # Finite, but squared in a norm: overflow, and a NaN scene.
    ("hsr_obstacles.yaml", "x_range: [1.25, 2.5]", "x_range: [-1.0e300, 2.5]",
     r"scenario.task.x_range\[0\]: -1e\+300 is too large; expected a number of size at most"),
    # A bent path of no length (its normal divided by zero) or an axis whose norm is 0.
    ("toy_alpha_study.yaml", "goal: [1.0, 0.0]", "goal: [1.0e-300, 0.0]",
     r"scenario.demonstration.goal \[1e-300, 0.0\] is where start is"),
    ("toy_alt_vs_cont.yaml", "axis: [0.0, 1.0]", "axis: [0.0, 1.0e-300]",
     r"scenario.operator.axis \[0.0, 1e-300\] is no direction; expected a vector of "
     r"dimension 2 and length at least 1e-6"),
    # Accepted, then the diagram was wired to an obstacle input the station did not have.
    ("hsr_obstacles.yaml", "obstacle_count: 3", "obstacle_count: 0",
     r"scenario.task.obstacle_count 0 is out of range; expected 1 to 100"),
    # A goal beyond the bound every running goal is held to (core.coordinates): a
    # ValueError from the goals source, with a traceback, when the diagram was built.
    ("toy_alpha_study.yaml", "goal: [1.0, 0.0]", "goal: [1.0e9, 0.0]",
     r"scenario.goals: goal 0 is \[1000000000.0, .*\]: positions must be finite and within "
     r"±1e\+06 m"),
    # Accepted as "not negative", then refused by the robot when the diagram was built.
    ("toy_alpha_study.yaml", "stiffness: 400.0", "stiffness: 0.0",
     r"scenario.robot.stiffness must be finite and positive, got 0.0"),
])
def test_values_that_broke_a_computation_are_refused(tmp_path, file, old, new, message):
    assert_edit_refused(tmp_path, file, old, new, message)


@pytest.mark.parametrize("old, new, message", [
    ("stall_time: 4.0", "stall_time: 0.0",
     r"scenario.operator.stall_time must be finite and positive, got 0.0"),
    ("settle_time: 4.0", "settle_time: -1.0",
     r"scenario.operator.settle_time must be finite and positive, got -1.0"),
    ("progress_step: 0.02", "progress_step: 0.0",
     r"scenario.operator.progress_step must be finite and positive"),
    # Divided by in the plan's turning score.
    ("max_turn_rate: 0.5", "max_turn_rate: 0.0",
     r"scenario.operator.max_turn_rate must be finite and positive, got 0.0"),
    ("release_heading_gap: 0.05", "release_heading_gap: -0.1",
     r"scenario.operator.release_heading_gap must be finite and positive"),
    ("policy_compensation: 3.0", "policy_compensation: 0.0",
     r"scenario.operator.policy_compensation must be finite and positive"),
    ("turn_weight: 0.6", "turn_weight: -0.6",
     r"scenario.operator.turn_weight must be finite and not negative, got -0.6"),
    ("final_approach_radius: 0.08", "final_approach_radius: -0.08",
     r"scenario.operator.final_approach_radius must be finite and not negative"),
    ("min_closing_fraction: 0.25", "min_closing_fraction: -1.0",
     r"scenario.operator.min_closing_fraction must be finite and not negative"),
    ("push_through_radius: 0.3", "push_through_radius: .nan",
     r"scenario.operator.push_through_radius: NaN is not a number here"),
    ("plan_directions: 24", "plan_directions: 0",
     r"scenario.operator.plan_directions 0 is out of range; expected 1 to 360"),
    ("plan_times: [0.1, 0.3, 0.6, 1.0, 1.5]", "plan_times: []",
     r"scenario.operator.plan_times \[\] must be 1 to 100 positive times \(s\) that increase "
     r"strictly"),
    ("plan_times: [0.1, 0.3, 0.6, 1.0, 1.5]", "plan_times: [0.1, 0.6, 0.3]",
     r"scenario.operator.plan_times \[0.1, 0.6, 0.3\] must be 1 to 100 positive times"),
    ("plan_times: [0.1, 0.3, 0.6, 1.0, 1.5]", "plan_times: [0.0, 0.3]",
     r"scenario.operator.plan_times \[0.0, 0.3\] must be 1 to 100 positive times"),
])
def test_a_bad_participant_value_is_refused_naming_its_field(tmp_path, old, new, message):
    assert_edit_refused(tmp_path, "hsr_obstacles.yaml", old, new, message)


def test_the_participant_fields_are_checked_in_the_reaching_task_too(tmp_path):
    text = (DIAGRAMS / "hsr_reach.yaml").read_text()
    path = tmp_path / "hsr_reach.yaml"
    path.write_text(text.replace("    speed_noise: 0.1\n",
                                 "    speed_noise: 0.1\n    policy_compensation: 0.0\n", 1))
    with pytest.raises(ScenarioError,
                       match=r"scenario.operator.policy_compensation must be finite and "
                             r"positive, got 0.0"):
        load_scenario_file(path)


@pytest.mark.parametrize("line, message", [
    # Divided by: a zero turned the participant's turn rate into a ZeroDivisionError, a
    # negative radius drove it away from the target.
    ("turn_slowdown_angle: 0.0", "turn_slowdown_angle must be finite and positive, got 0.0"),
    ("slow_radius: -0.15", "slow_radius must be finite and positive, got -0.15"),
    ("insist_time: -1.0", "insist_time must be finite and not negative, got -1.0"),
    ("reposition_time: -1.0", "reposition_time must be finite and not negative, got -1.0"),
    ("aligned_angle: -0.05", "aligned_angle must be finite and not negative"),
    ("aside_speed_fraction: -0.5", "aside_speed_fraction must be finite and not negative"),
    ("serve_speed_fraction: -0.5", "serve_speed_fraction must be finite and not negative"),
    ("serve_patience: .nan", "serve_patience: NaN is not a number here"),
    ("hold_time: -0.5", "hold_time must be finite and not negative"),
])
def test_a_bad_reaching_participant_value_is_refused_naming_its_field(tmp_path, line,
                                                                      message):
    text = (DIAGRAMS / "arm_reach.yaml").read_text()
    old = "    reaction_delay: 0.0\n"
    assert old in text
    path = tmp_path / "arm_reach.yaml"
    path.write_text(text.replace(old, f"{old}    {line}\n", 1))
    with pytest.raises(ScenarioError, match=rf"scenario.operator.{message}"):
        load_scenario_file(path)


@pytest.mark.parametrize("file, old, new, message", [
    # The targets of given objects: one per switch, each an object's index, none twice in a
    # row, and none without objects.
    ("hsr_reach.yaml", "    object_count: [2, 4]\n",
     "    objects: [[1.5, 0.3, 0.7], [1.5, -0.3, 0.7]]\n    targets: [0, 1]\n",
     r"scenario.task: targets \[0, 1\] needs one object index per entry of switch_schedule "
     r"\[0.0, 0.3, 0.6\]"),
    ("hsr_reach.yaml", "    object_count: [2, 4]\n",
     "    objects: [[1.5, 0.3, 0.7], [1.5, -0.3, 0.7]]\n    targets: [0, 1, 5]\n",
     r"scenario.task: targets \[0, 1, 5\] name objects that do not exist \(2 objects\)"),
    ("hsr_reach.yaml", "    object_count: [2, 4]\n",
     "    objects: [[1.5, 0.3, 0.7], [1.5, -0.3, 0.7]]\n    targets: [0, 0, 1]\n",
     r"scenario.task: targets \[0, 0, 1\]: each switch must go to a different object"),
    ("hsr_reach.yaml", "    object_count: [2, 4]\n", "    targets: [0, 1, 0]\n",
     r"scenario.task: targets are given without objects"),
    # The studies' lists, and what they need of the scenario.
    ("toy_alpha_study.yaml", "  alphas: [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0]",
     "  alphas: []", r"study.alphas is empty"),
    ("toy_alpha_study.yaml", "  demonstration: !BentPath {start: [0.0, 0.0], goal: [1.0, 0.0], "
     "bend: 0.3, duration: 1.0}\n", "  start: [0.0, 0.0]\n  goals: [[1.0, 0.0]]\n"
     "  dmp_duration: 1.0\n", r"the alpha study needs scenario.demonstration"),
    ("toy_alpha_study.yaml", "operator: !ObstacleRepulsion {distance_threshold: 0.2, speed: 2.0, "
     "axis: [0.0, 1.0]}", "operator: !SinusoidalStep {axis: [0.0, 1.0], amplitude: 1.0, "
     "start_time: 0.2, duration: 0.4, period: 1.6}",
     r"study.operator_speeds needs an operator with a speed, not !SinusoidalStep"),
    ("hsr_reach.yaml", "  methods: [pbp_alternated, pbp_continuous, teleop]", "  methods: []",
     r"study.methods is empty"),
    # What the robot tasks alone have, asked of a 2-D scene.
    ("toy_alt_vs_cont.yaml", "  control_period: 0.01\n",
     "  control_period: 0.01\n  goal_estimator: {group_mass: 0.5}\n",
     r"scenario.goal_estimator.group_mass: goal groups steer the DMPs of the robot tasks .*"
     r"this scenario has a point robot: set it to 0"),
    ("toy_alt_vs_cont.yaml", "  control_period: 0.01\n",
     "  control_period: 0.01\n  goal_estimator: {method: intent_filter}\n",
     r"scenario.goal_estimator.method intent_filter reads the hand's pose .* use angle in the "
     r"2-D scenes"),
    ("toy_alt_vs_cont.yaml", "basis_count: 50}", "basis_count: 50, primitive: x.json}",
     r"scenario.dmp.primitive gives a robot task's DMPs a taught shape; a 2-D scene learns "
     r"its shape from scenario.demonstration"),
    # Fixed alpha plays the demonstration to its one goal.
    ("toy_alt_vs_cont.yaml", "  method: pbp_alternated", "  method: fixed_alpha",
     r"scenario.method fixed_alpha plays the demonstration as P: give scenario.demonstration"),
    ("toy_alpha_study.yaml", "  method: pbp_alternated",
     "  method: fixed_alpha\n  goals: [[1.0, 0.0], [1.0, 1.0]]",
     r"scenario.method fixed_alpha takes exactly one goal here"),
    ("toy_alpha_study.yaml", "start: [0.0, 0.0], goal", "start: [0.0, 0.0, 0.0], goal",
     r"scenario.demonstration.start \[0.0, 0.0, 0.0\] and goal \[1.0, 0.0\]: a bent path is "
     r"2-D; expected two numbers each"),
    ("toy_alt_vs_cont.yaml", "  goals: [[1.0, 0.0]]", "  goals: [[1.0, 0.0, 0.0]]",
     r"scenario.goals have dimension 3, scenario.start has 2"),
    # The 2-D scenes' operators.
    ("toy_alpha_study.yaml", "distance_threshold: 0.2", "distance_threshold: 0.0",
     r"scenario.operator.distance_threshold must be finite and positive, got 0.0"),
    ("toy_alt_vs_cont.yaml", "period: 1.6}", "period: 0.0}",
     r"scenario.operator.amplitude must be finite, duration and period positive"),
    ("toy_alt_vs_cont.yaml", "  operator: !SinusoidalStep {axis: [0.0, 1.0], amplitude: 1.0, "
     "start_time: 0.2,\n                             duration: 0.4, period: 1.6}",
     "  operator: !ScriptedCommands {times: [0.0, 1.0], commands: [[0.0, 1.0]]}",
     r"scenario.operator.commands must be one command of dimension 2 per time"),
    # A hand that turns too slowly to reach the operator's rotation speed in the run.
    ("hsr_reach.yaml", "    speed: 0.12\n",
     "    speed: 0.12\n    max_hand_yaw_acceleration: 0.001\n",
     r"scenario.robot.max_hand_yaw_acceleration 0.001 rad/s\^2 takes 800.0 s to reach the "
     r"operator's rotation_speed 0.8 rad/s, longer than scenario.duration 60.0 s: raise it"),
    # Infinite is no limit in the acceleration limits only, and only upwards.
    ("hsr_reach.yaml", "motion: kinematic}",
     "motion: kinematic, arm_acceleration_limits: [-.inf, 1.0, .inf, 2.0, .inf]}",
     r"scenario.robot.station.arm_acceleration_limits\[0\]: -inf is infinite; expected a "
     r"finite number"),
])
def test_a_value_the_rest_of_the_scenario_cannot_use_is_refused(tmp_path, file, old, new,
                                                                 message):
    assert_edit_refused(tmp_path, file, old, new, message)


def test_infinite_acceleration_limits_are_no_limits(tmp_path):
    text = (DIAGRAMS / "hsr_reach.yaml").read_text()
    path = tmp_path / "hsr_reach.yaml"
    path.write_text(text.replace("motion: kinematic}", "motion: kinematic, "
                                 "arm_acceleration_limits: [.inf, 1.0, .inf, 2.0, .inf]}", 1))
    station = load_scenario_file(path).scenario.robot.station
    assert station.arm_acceleration_limits == [math.inf, 1.0, math.inf, 2.0, math.inf]


def test_a_gamepad_is_refused_where_the_objects_stand_at_heights_of_their_own(tmp_path):
    text = (DIAGRAMS / "arm_reach.yaml").read_text()
    path = tmp_path / "arm_reach.yaml"
    path.write_text(re.sub(r"  operator: !VirtualParticipant\n(    .*\n)+",
                           "  operator: !Gamepad {}\n", text, count=1))
    with pytest.raises(ScenarioError, match=r"scenario.operator !Gamepad has no up and down: "
                       r"a task whose objects stand at heights of their own \(scenario.task."
                       r"z_range\) takes !Keyboard or !VirtualParticipant"):
        load_scenario_file(path)


def test_a_scenario_made_in_python_is_held_to_the_checks_a_file_walk_cannot_make():
    toy = load_scenario_file(DIAGRAMS / "toy_alt_vs_cont.yaml").scenario
    reach = load_scenario_file(DIAGRAMS / "hsr_reach.yaml").scenario
    # An array is resolved as its list: the walk of the numbers names the element.
    commands = ScriptedCommands(times=[0.0, 1.0], commands=np.array([[0.0, np.nan],
                                                                     [0.0, 0.0]]))
    with pytest.raises(ScenarioError, match=r"^scenario.operator.commands\[0\]\[1\]: NaN is "
                                            r"not a number here; expected a finite number$"):
        resolve(dataclasses.replace(toy, operator=commands))
    participant = dataclasses.replace(reach.operator, plan_directions=2.5)
    with pytest.raises(ScenarioError, match=r"^scenario.operator.plan_directions 2.5 is no "
                                            r"count; expected a whole number, 1 to 360$"):
        resolve(dataclasses.replace(reach, operator=participant))
    # A number given as a string (as YAML would have read it): named, not a NumPy TypeError.
    with pytest.raises(ScenarioError, match=r"^scenario.duration must be finite and positive, "
                                            r"got '3'$"):
        resolve(dataclasses.replace(reach, duration="3"))
    with pytest.raises(ValueError, match=r"^x_range and y_range must be \[low, high\]$"):
        task_scene(MultiGoalReach(x_range=[1.0]), 0)
    with pytest.raises(ScenarioError, match=r"^study !MethodComparison runs the tasks: use "
                                            r"robot: !Hsr or !Arm$"):
        check_method_comparison(MethodComparison(), toy)


def test_a_primitive_file_larger_than_any_primitive_is_refused(tmp_path):
    path = tmp_path / "huge.json"
    with open(path, "wb") as file:
        file.truncate(MAX_PRIMITIVE_BYTES + 1)  # sparse: no disk is written
    with pytest.raises(ScenarioError, match=r"^scenario.dmp.primitive is over 64 MiB: not a "
                                            r"primitive$"):
        load_primitive(path, "scenario.dmp.primitive")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes")
@pytest.mark.timeout(60)
def test_a_primitive_file_that_is_a_pipe_is_refused_without_reading_it(tmp_path):
    path = tmp_path / "pipe.json"
    os.mkfifo(path)  # its open would wait for a writer
    with pytest.raises(ScenarioError, match=r"^scenario.dmp.primitive is not a regular "
                                            r"file: not a primitive$"):
        load_primitive(path, "scenario.dmp.primitive")


def assert_edit_refused(tmp_path, file, old, new, message):
    """The shipped `file` with its first `old` replaced by `new` is refused with `message`."""
    text = (DIAGRAMS / file).read_text()
    assert old in text, old
    path = tmp_path / file
    path.write_text(text.replace(old, new, 1))
    with pytest.raises(ScenarioError, match=message):
        load_scenario_file(path)
