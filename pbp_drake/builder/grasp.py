"""The grasping task's diagram: six-DoF PBP on the pose station (`make_hsr_station(...,
command="pose")`), the hand driven to a grasp pose (position and orientation). Under
``hop`` and ``predict_then_assist`` a `PoseHopAssistance` stands in for the DMP bank and
the blender; with `goal_estimator: {group_mass: M}` a `PoseGoalGrouping` stands between
`goal_poses` and the DMP bank. The wiring, the loggers (`hand_pose_log` for
`ee_state_log`, read by `grasp_series_fields`) and why: docs/tasks/grasp.md, "The
diagram"."""

import numpy as np
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput

from pbp_drake.builder.operators import make_person, shown_intent_and_keys
from pbp_drake.builder.pbp_controller import make_goal_estimator
from pbp_drake.builder.pilot_operators import make_pilot
from pbp_drake.core.dmp import DmpBankModel, OrientationDmpBank
from pbp_drake.core.dmp.primitive import primitive_bank, primitive_orientation_bank
from pbp_drake.core.grasp_task import approach_direction
from pbp_drake.core.methods import ASSISTED, METHODS
from pbp_drake.core.participant_grasp import GraspParticipant, GraspParticipantParams
from pbp_drake.core.pose_arbitration import HandOverLimits
from pbp_drake.core.quaternion import angle_between
from pbp_drake.robots import make_hsr_station
from pbp_drake.robots.hsr_station import hsr_initial_hand_pose
from pbp_drake.scenarios import (
    PILOT_CONFIGS, Gamepad, Keyboard, NoOperator, forward_key_enabled)
from pbp_drake.systems import (
    PoseVirtualOperator, GraspTaskMonitor, IdleOperator, PoseBlender, PoseDmpBank,
    PoseGoalGrouping, PoseHandOver, PoseHopAssistance, PoseMaxEntGoalEstimator, SampleHold)
from pbp_drake.systems.operators.pose_gamepad_operator import PoseGamepadOperator
from pbp_drake.systems.visualizers.grasp_scene_visualizer import GraspSceneVisualizer
from pbp_drake.systems.operators.pilot_filters import GraspKeys
from pbp_drake.systems.operators.pose_keyboard_operator import PoseKeyboardOperator
from pbp_drake.systems.ports import OperatorTwist

# The commanded angular velocity changes by at most this much (rad/s) between two
# ticks, so a goal switch or the operator pressing never jerks the wrist.
ANGULAR_CHANGE_PER_TICK = 0.3
# The hand's angular speed cap (rad/s): above the participant's 0.8 rad/s with its speed
# noise (10 %), so the cap does not slow the person, only a DMP far from its goal.
MAX_HAND_ANGULAR_SPEED = 1.0
# How many poses ahead the page draws the selected DMP's path, over the DMPs' duration (as
# the reach task's TASK_PREDICTION_SAMPLES).
GRASP_PREDICTION_SAMPLES = 40


def grasp_dmp_banks(resolved, start_pose):
    """The position and orientation banks, straight paths (or the taught primitive's pose
    shape) from the hand's `start_pose` `[p, q]` to the K grasp poses, of one duration
    (`resolved.controller.dmp_duration`) so that they share one phase."""
    scenario = resolved.scenario
    goals = resolved.scene.grasps.grasp_positions
    primitive = resolved.controller.dmp_primitive
    duration = resolved.controller.dmp_duration
    if primitive is not None:  # a taught pose's shape (`dmp.primitive`)
        return (primitive_bank(primitive, start_pose[:3], len(goals), duration),
                primitive_orientation_bank(primitive, start_pose[3:7], len(goals), duration))
    return (DmpBankModel.straight(start_pose[:3], len(goals), duration, scenario.dmp),
            OrientationDmpBank.straight(start_pose[3:7], len(goals), duration, scenario.dmp))


def build_grasp_diagram(resolved, meshcat=None):
    """The Diagram of a resolved grasping scenario; with `meshcat`, the robot drawn there."""
    scenario = resolved.scenario
    period = scenario.control_period
    task = scenario.task
    grasps = resolved.scene.grasps
    goal_count = len(grasps.grasp_positions)
    builder = DiagramBuilder()

    station = builder.AddNamedSystem("hsr_station", make_hsr_station(
        resolved.station, meshcat, command="pose"))
    start = hsr_initial_hand_pose(station)
    hand_pose = station.GetOutputPort("hand_pose")
    sample = builder.AddNamedSystem("hand_pose_sample", SampleHold(period, start))
    builder.Connect(hand_pose, sample.get_input_port())
    sampled = sample.get_output_port()

    poses = np.hstack([grasps.grasp_positions, grasps.grasp_orientations]).reshape(-1)
    goal_poses = builder.AddNamedSystem("goal_poses", ConstantVectorSource(poses))
    estimator = builder.AddNamedSystem("goal_estimator", _estimator(resolved, goal_count))
    builder.Connect(sampled, estimator.get_hand_pose_input_port())
    builder.Connect(goal_poses.get_output_port(), estimator.get_goal_poses_input_port())
    selected = estimator.get_selected_goal_output_port()
    probabilities = estimator.get_goal_probabilities_output_port()
    intent = selected  # the goal the robot shows: the selected one, or the grouping's

    limits = HandOverLimits(scenario.robot.max_hand_acceleration, scenario.robot.max_hand_speed,
                            ANGULAR_CHANGE_PER_TICK / period, MAX_HAND_ANGULAR_SPEED)
    method = METHODS[scenario.method]
    if method.policy == ASSISTED:
        # HOP and predict-then-assist: the operator's twist plus the assistance, no DMPs.
        dmp_bank = None
        prediction_steps = 0
        policy = builder.AddNamedSystem("assistance", PoseHopAssistance(
            method.assistance, goal_count, scenario.hop, period))
        builder.Connect(goal_poses.get_output_port(), policy.get_goal_poses_input_port())
    else:
        position_bank, orientation_bank = grasp_dmp_banks(resolved, start)
        prediction_steps = GRASP_PREDICTION_SAMPLES if meshcat is not None else 0
        # The hand-over's caps: no DMP winds its velocity up past what the hand may do. The
        # compact state (16 numbers, not 12 K): every DMP continues from the followed one's.
        dmp_bank = builder.AddNamedSystem("dmp_bank", PoseDmpBank(
            position_bank, orientation_bank, period,
            lock_phase_when_operator_acts=method.lock_phase,
            max_speed=limits.max_speed, max_angular_speed=limits.max_angular_speed,
            prediction_steps=prediction_steps, compact_state=True))
        builder.Connect(sampled, dmp_bank.get_robot_state_input_port())
        if scenario.goal_estimator.group_mass > 0.0:
            intent = _add_grouping(builder, resolved, goal_count, estimator, goal_poses,
                                   sampled, dmp_bank)
        else:
            builder.Connect(goal_poses.get_output_port(),
                            dmp_bank.get_goal_poses_input_port())
        # Read at the decide stage before the estimator updates: the goal followed last tick.
        builder.Connect(selected, dmp_bank.get_followed_goal_input_port())
        builder.Connect(selected, dmp_bank.get_selected_goal_input_port())
        policy = builder.AddNamedSystem("blender", PoseBlender(
            resolved.blend_mode, goal_count, period, scenario.alpha))
        builder.Connect(dmp_bank.get_selected_reference_output_port(),
                        policy.get_policy_reference_input_port())
        builder.Connect(selected, policy.get_selected_goal_input_port())
    shown, keys = shown_intent_and_keys(builder, scenario, intent)
    builder.Connect(sampled, policy.get_robot_state_input_port())
    builder.Connect(probabilities, policy.get_goal_probabilities_input_port())
    hand_over = builder.AddNamedSystem("hand_over", PoseHandOver(start[:7], limits, period))
    builder.Connect(policy.get_reference_output_port(), hand_over.get_reference_input_port())
    builder.Connect(hand_over.get_command_output_port(), station.GetInputPort("pose_command"))

    monitor = builder.AddNamedSystem("task_monitor", GraspTaskMonitor(
        grasps.grasp_positions, grasps.grasp_orientations, grasps.targets,
        task.switch_schedule, start[:7], task.success_distance,
        np.radians(task.success_angle), period))
    builder.Connect(sampled, monitor.get_hand_pose_input_port())

    operator = builder.AddNamedSystem("operator", _operator(resolved, grasps, meshcat))
    if operator.HasInputPort("hand_pose"):
        builder.Connect(sampled, operator.GetInputPort("hand_pose"))
        builder.Connect(monitor.get_target_output_port(), operator.GetInputPort("target"))
        builder.Connect(shown, operator.GetInputPort("selected_goal"))
        builder.Connect(keys, operator.GetInputPort("forward_key"))
    if operator.HasInputPort("hand_state"):
        # The sampled pose: the person's frame is the hand's as the tick saw it.
        builder.Connect(sampled, operator.GetInputPort("hand_state"))
    active = operator.get_operator_active_output_port()
    twist = operator.get_operator_command_output_port()
    builder.Connect(active, monitor.get_operator_active_input_port())
    if dmp_bank is not None:
        builder.Connect(active, dmp_bank.get_operator_active_input_port())
        builder.Connect(active, policy.get_operator_active_input_port())
    # The recursive estimators read whether the operator acts (HOP's own belief does not,
    # and leaves its port unread).
    if estimator.HasInputPort("operator_active"):
        builder.Connect(active, estimator.get_operator_active_input_port())
    if estimator.HasInputPort("shown_goal"):
        # What the operator sees: its intervention is against it (the estimator's outputs
        # are its state, so this closes no algebraic loop).
        builder.Connect(shown, estimator.get_shown_goal_input_port())
    builder.Connect(twist, policy.get_operator_twist_input_port())
    builder.Connect(twist, estimator.get_operator_twist_input_port())

    logged = [("hand_pose_log", hand_pose), ("operator_active_log", active),
              ("operator_command_log", twist),
              ("command_log", hand_over.get_command_output_port()),
              ("selected_goal_log", shown),
              ("target_log", monitor.get_target_output_port())]
    if dmp_bank is not None:
        logged.append(("phase_log", dmp_bank.get_phase_output_port()))
    if estimator.HasOutputPort("posterior_clipped"):
        logged.append(("posterior_clipped_log", estimator.GetOutputPort("posterior_clipped")))
    for name, port in logged:
        LogVectorOutput(port, builder, period).set_name(name)
    if meshcat is not None:
        visualizer = builder.AddNamedSystem("task_visualizer", GraspSceneVisualizer(
            meshcat, grasps, prediction_steps, task.table_size, task.object_radius,
            task.object_height, likely_triads=1 + scenario.likely_paths))
        builder.Connect(monitor.get_target_output_port(), visualizer.get_target_input_port())
        builder.Connect(shown, visualizer.get_selected_goal_input_port())
        if dmp_bank is not None:
            builder.Connect(dmp_bank.get_predicted_poses_output_port(),
                            visualizer.get_predicted_poses_input_port())
        # The measured pose, not the sample: the triad moves smoothly at 30 Hz.
        builder.Connect(hand_pose, visualizer.get_hand_state_input_port())
        builder.Connect(probabilities, visualizer.get_goal_probabilities_input_port())
    diagram = builder.Build()
    diagram.set_name(scenario.name)
    return diagram


def _add_grouping(builder, resolved, goal_count, estimator, goal_poses, hand_pose, dmp_bank):
    """Goal groups between the goals and the DMP bank (`PoseGoalGrouping`, distances in
    the task's pose error); returns the goal the robot shows."""
    scenario = resolved.scenario
    task = scenario.task
    grouping = builder.AddNamedSystem("goal_grouping", PoseGoalGrouping(
        goal_count, scenario.goal_estimator, scenario.control_period,
        task.success_distance / np.radians(task.success_angle)))
    builder.Connect(goal_poses.get_output_port(), grouping.get_goal_poses_input_port())
    builder.Connect(hand_pose, grouping.get_hand_pose_input_port())
    builder.Connect(estimator.get_goal_probabilities_output_port(),
                    grouping.get_goal_probabilities_input_port())
    builder.Connect(estimator.get_selected_goal_output_port(),
                    grouping.get_selected_goal_input_port())
    builder.Connect(grouping.get_followed_poses_output_port(),
                    dmp_bank.get_goal_poses_input_port())
    return grouping.get_shown_goal_output_port()


def _estimator(resolved, goal_count):
    """The goal estimator: HOP's posterior under hop and predict_then_assist (the most
    probable goal selected at once), else `make_goal_estimator`'s for grasp poses."""
    scenario = resolved.scenario
    if METHODS[scenario.method].policy == ASSISTED:
        return PoseMaxEntGoalEstimator(goal_count, scenario.hop, scenario.control_period)
    return make_goal_estimator(resolved.controller, goal_count, pose=True,
                               forward_key=forward_key_enabled(scenario))


def _operator(resolved, grasps, meshcat):
    scenario = resolved.scenario
    config = scenario.operator
    period = scenario.control_period
    if not METHODS[scenario.method].operated or isinstance(config, NoOperator):
        return IdleOperator(OperatorTwist.size, period)
    if isinstance(config, (Keyboard, Gamepad)):
        return make_person(resolved, meshcat, PoseKeyboardOperator, PoseGamepadOperator)
    if isinstance(config, PILOT_CONFIGS):  # a surrogate pilot (`scenarios.pilots`)
        return make_pilot(resolved, lambda participant: _operator(participant, grasps, meshcat),
                          GraspKeys)
    participant = GraspParticipant.create(
        GraspParticipantParams.from_virtual_participant(scenario.operator),
        resolved.nominal_speed,
        grasps.grasp_positions, grasps.grasp_orientations, scenario.seed)
    return PoseVirtualOperator(participant, period)


def _headings(orientations):
    """The floor angle of the approach axis z_H of each quaternion row (the station's
    `heading`)."""
    return np.array([np.arctan2(*approach_direction(q)[1::-1]) for q in orientations])


def grasp_series_fields(times, hand_poses, decisions, grasp_orientations):
    """A grasping TaskResult's time series fields, as `run.series_fields` gives a reach
    task's, from the `hand_pose_log` samples (T, 13) and the decision logs by name, already
    shifted. Headings are the approach axis' floor angle, `commands` `[p, v, heading]` of
    the pose command, `operator_commands` the operator's `[v, wz]`."""
    commands = decisions["command_log"]
    twists = decisions["operator_command_log"]
    targets = decisions["target_log"][:, 3].astype(int)
    orientations = hand_poses[:, 3:7]
    # Each tick's angle to its own target's grasp orientation (the same for q and -q).
    angles = np.degrees(angle_between(orientations.T, np.asarray(grasp_orientations)[targets].T))
    return dict(
        times=times,
        ee_positions=hand_poses[:, :3],
        headings=_headings(orientations),
        commands=np.column_stack([commands[:, :3], commands[:, 7:10],
                                  _headings(commands[:, 3:7])]),
        operator_active=decisions["operator_active_log"][:, 0] > 0.5,
        operator_commands=twists[:, [0, 1, 2, 5]],
        selected_goals=decisions["selected_goal_log"][:, 0].astype(int),
        targets=targets,
        in_collision=None,
        angles_to_target=angles,
        command_angular_velocities=commands[:, 10:13],
        operator_twists=twists,
        hand_orientations=orientations)
