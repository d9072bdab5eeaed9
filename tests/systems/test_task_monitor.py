"""TaskMonitor (and GraspTaskMonitor, its rules with grasp poses) in a small diagram: a hand
that slides along +x past two objects.

The hand moves at 0.1 m/s from the origin; object 0 stands at x = 1 and object 1 at x = 2.
The target switches to object 1 once the progress toward object 0 reaches 0.455 (the tick at
4.6 s) and the task succeeds within 0.055 m of object 1 (the tick at 19.5 s).
"""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator, SimulatorStatus
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from pbp_drake.systems.tasks.grasp_task_monitor import GraspTaskMonitor
from pbp_drake.systems.ports import EeState, PoseState, Target, TaskStatus
from pbp_drake.systems.tasks.task_monitor import SUCCESS_MESSAGE, TaskMonitor
from pbp_drake.systems.tick import report_offset

PERIOD = 0.1
SPEED = 0.1
OBJECTS = [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]
SWITCH_TIME = 4.6
SUCCESS_TIME = 19.5
# Ticks 0, 0.1, ..., 19.5 s are counted.
STEPS = 196


def zero_order_hold(breaks, values):
    return TrajectorySource(PiecewisePolynomial.ZeroOrderHold(breaks, [values]))


def build(acting_until=2.0, colliding=(10.0, 12.0)):
    builder = DiagramBuilder()
    monitor = builder.AddNamedSystem("task_monitor", TaskMonitor(
        OBJECTS, targets=[0, 1], switch_schedule=[0.0, 0.455], start=[0.0, 0.0, 0.0],
        success_distance=0.055, control_period=PERIOD))
    hand = np.zeros((EeState.size, 2))  # at 0 s and at 100 s
    begin, end = EeState(hand[:, 0]), EeState(hand[:, 1])
    end.x = SPEED * 100.0
    begin.vx = end.vx = SPEED
    ee_state = builder.AddSystem(TrajectorySource(
        PiecewisePolynomial.FirstOrderHold([0.0, 100.0], hand)))
    builder.Connect(ee_state.get_output_port(), monitor.get_ee_state_input_port())
    acting = ([0.0, acting_until, 100.0], [1.0, 0.0, 0.0]) if acting_until else ([0.0, 100.0],
                                                                               [0.0, 0.0])
    active = builder.AddSystem(zero_order_hold(*acting))
    builder.Connect(active.get_output_port(), monitor.get_operator_active_input_port())
    if colliding is not None:
        start, end = colliding
        collision = builder.AddSystem(
            zero_order_hold([0.0, start, end, 100.0], [0.0, 1.0, 0.0, 0.0]))
        builder.Connect(collision.get_output_port(), monitor.get_in_collision_input_port())
    return builder.Build(), monitor


def read(monitor, simulator):
    context = monitor.GetMyContextFromRoot(simulator.get_context())
    return (Target(monitor.get_target_output_port().Eval(context)),
            TaskStatus(monitor.get_task_status_output_port().Eval(context)))


def test_the_target_switches_at_the_progress_schedule():
    diagram, monitor = build()
    simulator = Simulator(diagram)
    simulator.AdvanceTo(SWITCH_TIME - PERIOD / 2)
    target, status = read(monitor, simulator)
    assert (target.index, target.x, status.stage) == (0, 1.0, 0)
    assert status.progress == pytest.approx(0.45, abs=1e-6)
    simulator.AdvanceTo(SWITCH_TIME + PERIOD / 2)
    target, status = read(monitor, simulator)
    assert (target.index, target.x, status.stage) == (1, 2.0, 1)
    # Progress now counts toward object 1 from the start: 1 - 1.54 / 2.
    assert status.progress == pytest.approx(0.23, abs=1e-6)
    assert not status.success


def test_success_stops_a_plain_simulator_with_the_task_time_of_the_success_tick():
    diagram, monitor = build()
    simulator = Simulator(diagram)
    result = simulator.AdvanceTo(60.0)
    assert result.reason() == SimulatorStatus.ReturnReason.kReachedTerminationCondition
    assert result.system() is monitor
    assert result.message() == SUCCESS_MESSAGE
    # It stops a millionth of a period after the success update, before anything else.
    assert simulator.get_context().get_time() == pytest.approx(
        SUCCESS_TIME + report_offset(PERIOD), abs=1e-9)
    target, status = read(monitor, simulator)
    assert status.success == 1.0 and status.stage == 1 and target.index == 1
    assert status.task_time == pytest.approx(SUCCESS_TIME, abs=1e-9)
    assert status.steps == STEPS
    assert monitor.counts(monitor.GetMyContextFromRoot(simulator.get_context())).steps == STEPS


def test_after_success_the_status_is_frozen_and_a_later_advance_stops_a_period_on():
    diagram, monitor = build()
    simulator = Simulator(diagram)
    simulator.AdvanceTo(60.0)
    frozen = read(monitor, simulator)[1][:].copy()
    result = simulator.AdvanceTo(60.0)
    assert result.reason() == SimulatorStatus.ReturnReason.kReachedTerminationCondition
    assert simulator.get_context().get_time() == pytest.approx(
        SUCCESS_TIME + PERIOD + report_offset(PERIOD), abs=1e-9)
    np.testing.assert_array_equal(read(monitor, simulator)[1][:], frozen)


def test_the_ratios_count_the_steps_with_operator_input_and_with_collisions():
    diagram, monitor = build(acting_until=2.0, colliding=(10.0, 12.0))
    simulator = Simulator(diagram)
    simulator.AdvanceTo(60.0)
    status = read(monitor, simulator)[1]
    # The ticks 0 to 1.9 s with input, 10 to 11.9 s in collision: 20 each.
    assert status.intervention_ratio == pytest.approx(20 / STEPS, abs=1e-12)
    assert status.collision_ratio == pytest.approx(20 / STEPS, abs=1e-12)


def test_the_collision_ratio_is_zero_when_nothing_measures_collisions():
    diagram, monitor = build(acting_until=None, colliding=None)
    simulator = Simulator(diagram)
    simulator.AdvanceTo(60.0)
    status = read(monitor, simulator)[1]
    assert status.success == 1.0
    assert status.intervention_ratio == 0.0 and status.collision_ratio == 0.0


def test_two_contexts_keep_their_own_counts():
    diagram, monitor = build()
    simulator = Simulator(diagram)
    simulator.AdvanceTo(SWITCH_TIME + PERIOD / 2)
    fresh = diagram.CreateDefaultContext()
    assert monitor.counts(monitor.GetMyContextFromRoot(fresh)).steps == 0
    assert monitor.counts(monitor.GetMyContextFromRoot(simulator.get_context())).stage == 1


def test_an_update_offset_past_the_period_is_refused():
    with pytest.raises(ValueError, match="update_offset"):
        TaskMonitor(OBJECTS, [0], [0.0], [0.0, 0.0, 0.0], 0.05, PERIOD, update_offset=PERIOD)



@pytest.mark.slow
def test_the_grasp_monitor_keeps_the_same_rules():
    # The hand slides as above, already at the grasp orientation: the same ticks switch and
    # succeed, with no collision port.
    builder = DiagramBuilder()
    level = [1.0, 0.0, 0.0, 0.0]
    monitor = builder.AddNamedSystem("task_monitor", GraspTaskMonitor(
        OBJECTS, [level, level], targets=[0, 1], switch_schedule=[0.0, 0.455],
        start_pose=[0.0, 0.0, 0.0, *level], success_distance=0.055,
        success_angle=np.radians(10.0), control_period=PERIOD))
    assert [monitor.get_input_port(i).get_name() for i in range(monitor.num_input_ports())] \
        == ["hand_pose", "operator_active"]
    hand = np.zeros((PoseState.size, 2))
    hand[3, :] = 1.0
    hand[0, 1] = SPEED * 100.0
    pose = builder.AddSystem(TrajectorySource(
        PiecewisePolynomial.FirstOrderHold([0.0, 100.0], hand)))
    builder.Connect(pose.get_output_port(), monitor.get_hand_pose_input_port())
    active = builder.AddSystem(zero_order_hold([0.0, 2.0, 100.0], [1.0, 0.0, 0.0]))
    builder.Connect(active.get_output_port(), monitor.get_operator_active_input_port())
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(SWITCH_TIME + PERIOD / 2)
    target, status = read(monitor, simulator)
    assert (target.index, target.x, status.stage) == (1, 2.0, 1)
    result = simulator.AdvanceTo(60.0)
    assert result.reason() == SimulatorStatus.ReturnReason.kReachedTerminationCondition
    assert result.message() == SUCCESS_MESSAGE
    target, status = read(monitor, simulator)
    assert status.success == 1.0 and target.index == 1 and status.steps == STEPS
    assert status.task_time == pytest.approx(SUCCESS_TIME, abs=1e-9)
    assert status.intervention_ratio == pytest.approx(20 / STEPS, abs=1e-12)
    assert status.collision_ratio == 0.0


def test_a_switch_schedule_without_one_target_per_entry_is_refused():
    with pytest.raises(ValueError, match="one target per entry of switch_schedule"):
        TaskMonitor(OBJECTS, [0, 1], [0.0], [0.0, 0.0, 0.0], 0.05, PERIOD)


@pytest.mark.parametrize("change, message", [
    ({"objects": []}, r"objects must be a non-empty finite \(M, 3\) array, got shape \(0,\)"),
    ({"objects": [[0.5, 0.0]]}, r"objects must be .* got shape \(1, 2\)"),
    ({"objects": [[np.nan, 0.0, 0.4]]}, r"objects must be a non-empty finite \(M, 3\) array"),
    ({"targets": [2]}, r"targets must be object indices 0 to 1, got \[2\]"),
    ({"targets": [-1]}, r"targets must be object indices 0 to 1, got \[-1\]"),
    ({"targets": [0.5]}, r"targets must be object indices 0 to 1, got \[0.5\]"),
    # No target failed with an IndexError at the first tick.
    ({"targets": [], "switch_schedule": []},
     r"targets must name at least one object \(its index in objects\), got none"),
    ({"switch_schedule": [np.nan]}, r"switch_schedule must be finite, got \[nan\]"),
    ({"start": [0.0, 0.0]}, r"start must be 3 finite numbers \[x, y, z\], got \[0.0, 0.0\]"),
    ({"start": [np.nan, 0.0, 0.0]}, r"start must be 3 finite numbers"),
    ({"success_distance": 0.0}, r"success_distance must be finite and positive \(m\), got 0.0"),
    ({"success_distance": -0.05}, r"success_distance must be finite and positive"),
    ({"success_distance": np.nan}, r"success_distance must be finite and positive"),
    ({"success_distance": None}, r"success_distance must be a number \(m\), got None"),
])
def test_the_monitor_names_an_argument_it_cannot_referee(change, message):
    arguments = {"objects": OBJECTS, "targets": [0], "switch_schedule": [0.0],
                 "start": [0.0, 0.0, 0.0], "success_distance": 0.05, "control_period": PERIOD}
    with pytest.raises(ValueError, match=message):
        TaskMonitor(**{**arguments, **change})


@pytest.mark.parametrize("change, message", [
    ({"grasp_positions": [[0.5, 0.0]]}, r"grasp_positions must be a non-empty finite \(M, 3\)"),
    ({"success_angle": 0.0}, r"success_angle must be finite and positive \(rad\), got 0.0"),
    ({"success_distance": np.inf}, r"success_distance must be finite and positive"),
    ({"grasp_orientations": [[1.0, 0.0, 0.0, 0.0]]},
     r"grasp_orientations must be one quaternion .* per grasp position, \(2, 4\), got shape "
     r"\(1, 4\)"),
    ({"grasp_orientations": [[1.0, 0.0, 0.0]] * 2}, r"grasp_orientations must be one quaternion"),
    ({"grasp_orientations": [[np.nan, 0.0, 0.0, 0.0]] * 2},
     "grasp_orientations contains NaN or infinite values"),
    ({"grasp_orientations": [[2.0, 0.0, 0.0, 0.0]] * 2},
     "grasp_orientations is not a unit quaternion"),
    ({"start_pose": [0.0, 0.0, 0.0]}, r"start_pose must be 7 finite numbers .*, got \[0.0, 0.0, "),
    ({"start_pose": [0.0, np.nan, 0.0, 1.0, 0.0, 0.0, 0.0]}, "start_pose must be 7 finite"),
    ({"start_pose": [0.0] * 7}, "start_pose orientation is not a unit quaternion"),
])
def test_the_grasp_monitor_names_an_argument_it_cannot_referee(change, message):
    level = [1.0, 0.0, 0.0, 0.0]
    arguments = {"grasp_positions": OBJECTS, "grasp_orientations": [level, level],
                 "targets": [0], "switch_schedule": [0.0], "start_pose": [0.0] * 3 + level,
                 "success_distance": 0.05, "success_angle": 0.2, "control_period": PERIOD}
    with pytest.raises(ValueError, match=message):
        GraspTaskMonitor(**{**arguments, **change})


def test_a_nan_hand_is_refused_by_the_monitor_naming_the_field():
    monitor = TaskMonitor(OBJECTS, [0], [0.0], [0.0, 0.0, 0.0], 0.05, PERIOD)
    simulator = Simulator(monitor)
    context = monitor.GetMyContextFromRoot(simulator.get_mutable_context())
    monitor.get_ee_state_input_port().FixValue(context, [0.0, np.nan] + [0.0] * 6)
    monitor.get_operator_active_input_port().FixValue(context, [0.0])
    with pytest.raises(ValueError, match=r"ee_state y is NaN or infinite: \[0.0, nan"):
        simulator.AdvanceTo(PERIOD)


def test_a_nan_hand_is_refused_by_the_grasp_monitor_naming_the_field():
    level = [1.0, 0.0, 0.0, 0.0]
    monitor = GraspTaskMonitor(OBJECTS, [level, level], [0], [0.0], [0.0] * 3 + level, 0.05,
                               0.2, PERIOD)
    simulator = Simulator(monitor)
    context = monitor.GetMyContextFromRoot(simulator.get_mutable_context())
    monitor.get_hand_pose_input_port().FixValue(context, [0.0, np.nan, 0.0, *level] + [0.0] * 6)
    monitor.get_operator_active_input_port().FixValue(context, [0.0])
    with pytest.raises(ValueError, match=r"hand_pose y is NaN or infinite: \[0.0, nan"):
        simulator.AdvanceTo(PERIOD)
