"""The HSR reaching task end to end: the scenario file, PBP and teleop with the virtual
participant, goal switching, the keyboard in the full task, the CLI and bad input."""

import csv
import dataclasses
import io
import json
import math
import textwrap

import msgpack
import numpy as np
import pytest
from pydrake.geometry import Meshcat, MeshcatParams
from pydrake.systems.analysis import Simulator, SimulatorStatus

from pbp_drake.builder import build_diagram
from pbp_drake.cli import main
from pbp_drake.scenarios import Keyboard, ScenarioError, load_scenario_file
from pbp_drake.systems.ports import TaskStatus
from pbp_drake.systems.operators.keyboard_operator import LEFT_BUTTON
from pbp_drake.builder.run import run_task

# Whole tasks, studies, notebooks, browsers or pip: `make test-fast` leaves these out.
pytestmark = pytest.mark.slow

# Two objects ahead, left and right; the target starts on the right, switches to the left
# at 30 % and back at 60 %: both switches need the operator.
FIXED_TASK = """
scenario:
  name: two_objects
  method: pbp_alternated
  control_period: 0.03
  duration: 40.0
  robot: !Hsr {}
  task:
    objects: [[1.6, -0.5, 0.7], [1.6, 0.5, 0.7]]
    targets: [0, 1, 0]
  operator: !VirtualParticipant {}
  seed: 3
"""


def write(tmp_path, text, name="task.yaml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


@pytest.fixture(scope="module")
def fixed_task(tmp_path_factory):
    return load_scenario_file(write(tmp_path_factory.mktemp("task"), FIXED_TASK)).scenario


@pytest.fixture(scope="module")
def pbp_run(fixed_task):
    return run_task(fixed_task)


def test_pbp_alternated_reaches_the_switching_target_with_little_input(pbp_run):
    assert pbp_run.success
    assert pbp_run.switches == 2
    assert np.linalg.norm(pbp_run.ee_positions[-1] - pbp_run.objects[0]) < 0.06
    # The participant acts only to turn toward each new target; the DMPs do the rest.
    assert 0.0 < pbp_run.intervention_ratio < 0.5
    # In PBP the operator never pushes forward: the DMP phase does.
    assert np.all(pbp_run.operator_commands[:, 2] == 0.0)


def test_the_peaks_are_those_of_the_time_series_columns(fixed_task, pbp_run):
    # Recomputed here from the CSV a study would write: the largest step between ticks of
    # the hand (ee_x..ee_z) and of the commanded velocity (command_vx..vz), over the period.
    from pbp_drake.studies.trial_files import time_series_csv

    rows = list(csv.DictReader(io.StringIO(time_series_csv(pbp_run))))
    assert len(rows) == len(pbp_run.times)

    def peak(columns):
        points = [[float(row[column]) for column in columns] for row in rows]
        steps = [math.dist(a, b) for a, b in zip(points, points[1:])]
        return max(steps) / fixed_task.control_period

    assert pbp_run.peak_hand_speed == pytest.approx(peak(("ee_x", "ee_y", "ee_z")),
                                                    rel=1e-12)
    assert pbp_run.peak_command_acceleration == pytest.approx(
        peak(("command_vx", "command_vy", "command_vz")), rel=1e-12)
    assert pbp_run.peak_hand_speed > 0.0 and pbp_run.peak_command_acceleration > 0.0


def test_the_estimated_goal_follows_the_target(pbp_run):
    # At the end the estimate agrees with the target; it changed at least once per switch.
    assert pbp_run.selected_goals[-1] == pbp_run.targets[-1]
    assert np.count_nonzero(np.diff(pbp_run.selected_goals)) >= 2


def test_switching_goal_moves_the_command_no_more_than_one_step(pbp_run):
    positions = pbp_run.commands[:, :3]
    jumps = np.linalg.norm(np.diff(positions, axis=0), axis=1)
    switches = np.flatnonzero(np.diff(pbp_run.selected_goals)) + 1
    assert len(switches) >= 2
    travel = np.linalg.norm(np.diff(pbp_run.ee_positions, axis=0), axis=1)
    # One control step's travel: the most the end effector itself moves in one tick.
    step_travel = travel.max()
    assert step_travel < 0.02
    assert np.all(jumps[switches - 1] <= step_travel + 1e-3), (
        jumps[switches - 1], step_travel)


def test_the_blend_is_computed_once_per_control_tick(fixed_task, monkeypatch):
    # Between ticks nothing the blender reads changes; redoing it at every 5 ms plant step
    # (as behind Drake's Demultiplexer) cost the closed loop a fifth of its speed.
    from pbp_drake.systems.pbp.blender import Blender

    calls = []
    original = Blender._calc_command
    monkeypatch.setattr(Blender, "_calc_command",
                        lambda self, context, output: (calls.append(context.get_time()),
                                                       original(self, context, output)))
    simulator = Simulator(build_diagram(fixed_task))
    simulator.AdvanceTo(0.6)
    # One per tick, at its report stage where the hand-over reads it (the tick at 0.6 s
    # reports just after the end), and maybe at the operator's own moment.
    ticks = round(0.6 / fixed_task.control_period)
    assert ticks <= len(calls) <= 2 * ticks
    assert len(calls) < round(0.6 / fixed_task.robot.station.plant.time_step)


def test_a_plain_simulator_of_the_built_task_stops_at_success(fixed_task, pbp_run):
    # No runner, no monitor callback: the task monitor ends the simulation itself.
    diagram = build_diagram(fixed_task)
    simulator = Simulator(diagram)
    result = simulator.AdvanceTo(60.0)
    assert result.reason() == SimulatorStatus.ReturnReason.kReachedTerminationCondition
    monitor = diagram.GetSubsystemByName("task_monitor")
    status = TaskStatus(monitor.get_task_status_output_port().Eval(
        monitor.GetMyContextFromRoot(simulator.get_context())))
    assert status.success == 1.0
    assert simulator.get_context().get_time() < pbp_run.task_time + fixed_task.control_period
    assert (status.task_time, status.intervention_ratio, status.stage) == (
        pbp_run.task_time, pbp_run.intervention_ratio, pbp_run.switches)


def test_the_same_seed_gives_the_same_run(fixed_task, pbp_run):
    again = run_task(fixed_task)
    assert again.task_time == pbp_run.task_time
    np.testing.assert_array_equal(again.ee_positions, pbp_run.ee_positions)


def test_keyboard_left_key_moves_the_hand_left(fixed_task):
    meshcat = Meshcat(MeshcatParams(host="localhost", port=0))
    scenario = dataclasses.replace(fixed_task, method="teleop", operator=Keyboard())
    diagram = build_diagram(scenario, meshcat)
    simulator = Simulator(diagram)
    simulator.Initialize()
    station_state = diagram.GetSubsystemByName("ee_state_sample")
    start = station_state.get_output_port().Eval(
        station_state.GetMyContextFromRoot(simulator.get_context()))[:3].copy()
    for step in range(20):
        meshcat._InjectWebsocketMessage(msgpack.packb({"type": "button", "name": LEFT_BUTTON}))
        simulator.AdvanceTo(0.1 * (step + 1))
    end = station_state.get_output_port().Eval(
        station_state.GetMyContextFromRoot(simulator.get_context()))[:3]
    moved = end - start
    # The hand points along +x, so its left is +y.
    assert moved[1] > 0.15  # 2 s at the keyboard speed, less the hand-over ramps
    assert abs(moved[0]) < 0.05 and abs(moved[2]) < 0.02


def test_a_goal_moved_out_of_the_world_mid_run_stops_the_run_with_one_message(fixed_task,
                                                                              capfd):
    diagram = build_diagram(fixed_task)
    simulator = Simulator(diagram)
    simulator.Initialize()
    simulator.AdvanceTo(1.0)
    source = diagram.GetSubsystemByName("goals")  # the controller reads it on its port
    context = source.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    moved = source.get_goals_output_port().Eval(context).reshape(-1, 3).copy()
    moved[1, 0] = 1e200
    with pytest.raises(ValueError, match=r"goal 1 is \[1e\+200, "):
        source.set_goals(context, moved)
    # Written past set_goals (as a diagram of one's own may feed its goals), the DMP bank
    # refuses it at the next tick, before anything reaches the whole-body QP.
    context.get_mutable_numeric_parameter(0).SetFromVector(moved.reshape(-1))
    with pytest.raises(ValueError, match=r"goal 1 is .*positions must be finite and within"):
        simulator.AdvanceTo(1.5)
    output = capfd.readouterr()
    assert "OSQP" not in output.out + output.err
    assert "DifferentialInverseKinematics" not in output.out + output.err


def test_run_with_the_virtual_participant_prints_one_result_line(tmp_path, capsys, fixed_task,
                                                                 pbp_run):
    path = write(tmp_path, FIXED_TASK)
    record = tmp_path / "replay.html"
    code = main(["run", str(path), "--operator", "virtual", "--headless",
                 "--record", str(record)])
    out = capsys.readouterr().out
    assert code == 0
    assert "success in" in out and "intervention ratio" in out
    # The same seeded run as pbp_run: the line gives its peaks.
    assert (f", peak hand speed {pbp_run.peak_hand_speed:.3f} m/s, peak command "
            f"acceleration {pbp_run.peak_command_acceleration:.2f} m/s^2") in out
    # And how the participant and PBP worked together.
    assert (f", input {pbp_run.input_integral:.3f} m and {pbp_run.turn_input_integral:.3f} "
            f"rad, idle ratio {pbp_run.idle_ratio:.3f}, agreement {pbp_run.agreement:.3f}, "
            f"prediction accuracy {pbp_run.prediction_accuracy:.3f}") in out
    assert record.stat().st_size > 10_000


@pytest.mark.parametrize("change, message", [
    (("objects: [[1.6, -0.5, 0.7], [1.6, 0.5, 0.7]]\n    targets: [0, 1, 0]",
      "objects: [[1.6, 0.0, 0.7]]\n    targets: [0, 0, 0]"), "at least 2 objects"),
    (("[1.6, 0.5, 0.7]", "[1.6, -0.45, 0.7]"), "overlap"),
    (("[1.6, 0.5, 0.7]", "[6.0, 0.5, 0.7]"), "out of reach"),
    (("[1.6, 0.5, 0.7]", "[1.6, 0.5, 2.5]"), "out of the HSR's reach"),
    (("method: pbp_alternated", "method: pbp_alternatd"), "did you mean 'pbp_alternated'"),
    (("!VirtualParticipant {}", "!Virtual {}"), "Virtual"),
    (("robot: !Hsr {}", "robot: !Hsr {station: {diff_ik_time_step: 0.007}}"), "whole multiple"),
])
def test_bad_task_input_names_the_problem(tmp_path, change, message):
    path = write(tmp_path, FIXED_TASK.replace(*change))
    with pytest.raises(ScenarioError, match=message):
        load_scenario_file(path)


def test_one_object_with_switching_on_is_refused(tmp_path):
    text = FIXED_TASK.replace(
        "objects: [[1.6, -0.5, 0.7], [1.6, 0.5, 0.7]]\n    targets: [0, 1, 0]",
        "object_count: [1, 1]")
    with pytest.raises(ScenarioError, match="switching needs at least 2 objects"):
        load_scenario_file(write(tmp_path, text))


def test_unknown_operator_on_the_command_line(tmp_path, capsys):
    assert main(["run", str(write(tmp_path, FIXED_TASK)), "--operator", "joystik",
                 "--headless"]) == 2
    assert "--operator 'joystik' is unknown" in capsys.readouterr().err


def test_a_person_cannot_drive_a_headless_run(tmp_path, capsys):
    assert main(["run", str(write(tmp_path, FIXED_TASK)), "--operator", "keyboard",
                 "--headless"]) == 2
    assert "--operator virtual" in capsys.readouterr().err


def test_a_participant_session_runs_every_method_in_a_counterbalanced_order(tmp_path):
    from pbp_drake.studies.sessions import session_order

    methods = ["pbp_alternated", "pbp_continuous", "teleop"]
    orders = [session_order(methods, f"P{number}") for number in range(3)]
    # A cyclic Latin square: each method once in each place over three participants.
    for place in range(3):
        assert sorted(order[place] for order in orders) == sorted(methods)

    path = write(tmp_path, FIXED_TASK)
    output = tmp_path / "P1"
    assert main(["run", str(path), "--operator", "virtual", "--headless", "--participant",
                 "P1", "--methods", "pbp_alternated,teleop", "--answers", "tiredness=3,ease=4",
                 "--output", str(output)]) == 0
    study = json.loads((output / "study.json").read_text())
    assert study["methods"] == ["teleop", "pbp_alternated"]
    summary = json.loads((output / "summary.json").read_text())
    assert summary["methods"]["teleop"]["success_rate"] == 1.0
    # Teleop's participant drives the whole way (the session's teleop run of the task).
    (teleop,) = (output / "trials" / "teleop").glob("seed_*.json")
    record = json.loads(teleop.read_text())
    assert record["success"] and record["intervention_ratio"] > 0.85
    assert main(["report", str(output)]) == 0


def test_a_session_needs_a_participant_id(tmp_path, capsys):
    path = write(tmp_path, FIXED_TASK)
    assert main(["run", str(path), "--operator", "virtual", "--headless",
                 "--methods", "teleop"]) == 2
    assert "--participant" in capsys.readouterr().err
