"""Values the random mutations (test_random_mutations.py) found getting past the checks
into a division, a norm or a simulation: each now refused, naming its field."""

import pathlib

import pytest

from pbp_drake.scenarios import ScenarioError, load_scenario_file

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
    text = (DIAGRAMS / file).read_text()
    assert old in text, old
    path = tmp_path / file
    path.write_text(text.replace(old, new, 1))
    with pytest.raises(ScenarioError, match=message):
        load_scenario_file(path)
