"""A simulated HSR that follows an end-effector command, as one Diagram in the shape of
manipulation's hardware station (docs/tasks/hsr-station.md)::

    ee_command ─► WholeBodyDiffIk (its EeCommandRamp: X_WE_desired, V_WE_desired)
    WholeBodyDiffIk ─► [q_d, v_d] (desired_state) ─► the plant's PD on every motor
    plant ─► EeStateFromPlant ─► ee_state
    obstacle_positions ─► CylinderObstacleGeometry ─► SceneGraph ─► CollisionMonitor

One differential IK solves the base and the arm together within the joints' limits, and
stiff servos hold the robot on its plan; gravity is off. ``command="pose"`` is the six-DoF
station (docs/concepts/six-dof.md).

Example::

    station = make_hsr_station()
    builder = DiagramBuilder()
    builder.AddNamedSystem("hsr_station", station)
    hold = builder.AddSystem(ConstantVectorSource(hsr_initial_ee_state(station)[:7]))
    builder.Connect(hold.get_output_port(), station.GetInputPort("ee_command"))
"""

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import PdControllerGains
from pydrake.systems.framework import Diagram, DiagramBuilder

from pbp_drake.robots.hsr_diff_ik import WholeBodyDiffIk
from pbp_drake.robots.hsr_ee_systems import ee_state_at_rest, station_ramp
from pbp_drake.robots.hsr_model import (
    ACTUATED_JOINT_NAMES,
    ARM_JOINT_NAMES,
    BASE_JOINT_NAMES,
    END_EFFECTOR_FRAME,
    TORSO_JOINT_NAME,
    TORSO_TO_ARM_LIFT_RATIO,
    actuator_name,
    add_hsr,
)
from pbp_drake.robots.hsr_pose_systems import HAND_FRAME, PoseCommandRamp, PoseStateFromPlant
from pbp_drake.robots.station_parts import (
    add_robot, add_station_plant, checked_station, finish_station, initial_ee_state, pose_at,
    station_plant)
from pbp_drake.robots.hsr_station_config import HsrStationConfig, validate_hsr_station_config

# Ready pose: the arm leans forward by READY_ARM_FLEX and the wrist levels the hand, so
# the hand starts in front of the base with room to move both ways along x with the
# arm alone; arm_lift then sets the height.
READY_ARM_FLEX = -0.5
# make_hsr_station's commands: an EeCommand of hand_ee_link, a PoseState of hand_palm_link.
COMMANDS = ("heading", "pose")


def ready_positions(plant, model, initial_base=(0.0, 0.0, 0.0), ee_height=0.7):
    """Plant positions with the base at ``initial_base`` and the hand level and pointing
    along the base's +x at height ``ee_height`` in front of the base.

    Solved analytically: the flex and wrist flex joints both turn about the arm's -y,
    so a wrist flex of ``-pi/2 - arm_flex`` levels the hand; the lift then adds height
    one to one.
    """
    q = plant.GetDefaultPositions()

    def set_position(name, value):
        q[plant.GetJointByName(name, model).position_start()] = value

    for name, value in zip(BASE_JOINT_NAMES, initial_base):
        joint = plant.GetJointByName(name, model)
        if not joint.position_lower_limits()[0] <= value <= joint.position_upper_limits()[0]:
            raise ValueError(f"initial_base {list(initial_base)} is out of {name}'s range")
        set_position(name, value)
    set_position("arm_flex_joint", READY_ARM_FLEX)
    set_position("wrist_flex_joint", -np.pi / 2 - READY_ARM_FLEX)
    ee = plant.GetFrameByName(END_EFFECTOR_FRAME, model)
    arm_lift = plant.GetJointByName("arm_lift_joint", model)
    lift = ee_height - pose_at(plant, ee, q).translation()[2]
    if not arm_lift.position_lower_limits()[0] <= lift <= arm_lift.position_upper_limits()[0]:
        raise ValueError(f"ee_height {ee_height} m is out of the arm lift's range")
    set_position("arm_lift_joint", lift)
    # Keep the torso coupler satisfied from the start, or SAP would snap it at t = 0.
    set_position(TORSO_JOINT_NAME, TORSO_TO_ARM_LIFT_RATIO * lift)
    return q


def _ready_pose(plant, model, config, frame_name=END_EFFECTOR_FRAME):
    """The ready positions of `config` (see `ready_positions`) and the pose there of the
    frame `frame_name` (default: the hand's)."""
    q0 = ready_positions(plant, model, config.initial_base, config.ee_height)
    return q0, pose_at(plant, plant.GetFrameByName(frame_name, model), q0)


def _make_diff_ik(plant, model, q0, config, motor_joints, command_ramp, look_ahead,
                  frame_name=END_EFFECTOR_FRAME):
    """The whole-body diff IK of ``frame_name`` within the model's position and velocity
    limits and the config's acceleration limits, the arm drifting back to ``q0``."""
    v_lower, v_upper = plant.GetVelocityLowerLimits(), plant.GetVelocityUpperLimits()
    # The torso does not move the hand (it carries only the head) and follows the lift
    # through the coupler in the plant, so diff IK leaves it where it is.
    torso = plant.GetJointByName(TORSO_JOINT_NAME, model).velocity_start()
    v_lower[torso] = v_upper[torso] = 0.0
    accelerations = np.full(plant.num_velocities(), np.inf)
    centering = np.zeros(plant.num_positions())
    limits = config.base_acceleration_limits + config.arm_acceleration_limits
    for name, limit in zip(ACTUATED_JOINT_NAMES, limits):
        joint = plant.GetJointByName(name, model)
        accelerations[joint.velocity_start()] = limit
        if name in ARM_JOINT_NAMES:
            centering[joint.position_start()] = config.arm_centering_gain
    return WholeBodyDiffIk(
        plant, plant.GetFrameByName(frame_name, model), config.diff_ik_time_step,
        look_ahead, motor_joints,
        position_limits=(plant.GetPositionLowerLimits(), plant.GetPositionUpperLimits()),
        velocity_limits=(v_lower, v_upper), acceleration_limits=(-accelerations, accelerations),
        q_nominal=q0, centering_gain=centering, command_ramp=command_ramp,
        limit_overshoot=isinstance(command_ramp, PoseCommandRamp))


def make_hsr_station(config: HsrStationConfig | None = None, meshcat=None,
                     command: str = "heading") -> Diagram:
    """The HSR, its whole-body end-effector controller, and optionally obstacles and a
    Meshcat visualizer, as one Diagram named ``hsr_station``.

    Args:
        config: the station's knobs (``HsrStationConfig()`` when None).
        meshcat: if given, a MeshcatVisualizer inside draws the robot and the obstacles.
        command: ``"heading"`` (the hand follows ``ee_command``) or ``"pose"`` (the palm
            frame ``hand_palm_link`` follows ``pose_command`` and ``hand_pose`` is output).

    .. pydrake_system::

        name: hsr_station
        input_ports:
        - ee_command (command="heading")
        - pose_command (command="pose")
        - obstacle_positions (with config.obstacles)
        output_ports:
        - ee_state
        - hand_pose (command="pose")
        - state
        - desired_state
        - body_poses
        - query_object
        - in_collision (with config.obstacles)
        - clearance (with config.obstacles)

    The ports' sizes and contents: docs/tasks/hsr-station.md, "Ports" (``desired_state``
    in motor order, ``ACTUATED_JOINT_NAMES``; no ``body_poses`` with ``motion: kinematic``,
    whose plant is outside the Diagram: ``hsr_station_plant``); the pose station's
    (``PoseCommandRamp``, ``PoseStateFromPlant``): docs/concepts/six-dof.md, "The HSR pose
    station".

    A fresh context starts at rest in the ready pose with the diff IK already there, so
    holding ``hsr_initial_ee_state(station)[:7]`` keeps the robot still.
    """
    config = config if config is not None else HsrStationConfig()
    validate_hsr_station_config(config)
    if command not in COMMANDS:
        raise ValueError(f"make_hsr_station command must be one of {COMMANDS}, got "
                         f"{command!r}")
    builder = DiagramBuilder()
    kinematic = config.motion == "kinematic"
    plant, scene_graph = add_station_plant(builder, config, kinematic)
    model = add_hsr(plant)
    gains = zip(ACTUATED_JOINT_NAMES, config.base_kp + config.arm_kp,
                config.base_kd + config.arm_kd)
    for name, kp, kd in gains:
        plant.GetJointActuatorByName(actuator_name(name), model).set_controller_gains(
            PdControllerGains(p=kp, d=kd))
    plant.Finalize()

    q0, X_WE0 = _ready_pose(plant, model, config)
    plant.SetDefaultPositions(q0)
    ramp = station_ramp(X_WE0, config)
    frame_name = END_EFFECTOR_FRAME
    if command == "pose":
        ramp = PoseCommandRamp(config.control_period, lead=config.diff_ik_time_step)
        frame_name = HAND_FRAME
    motor_joints = [plant.get_joint_actuator(index).joint()
                    for index in plant.GetJointActuatorIndices(model)]
    look_ahead = 0.0 if kinematic else config.plant.time_step
    diff_ik = builder.AddNamedSystem("diff_ik", _make_diff_ik(
        plant, model, q0, config, motor_joints, ramp, look_ahead, frame_name))
    couplers = [(plant.GetJointByName(TORSO_JOINT_NAME, model),
                 plant.GetJointByName("arm_lift_joint", model), TORSO_TO_ARM_LIFT_RATIO)]
    state = add_robot(
        builder, plant, scene_graph, model, diff_ik, ramp,
        plant.GetFrameByName(END_EFFECTOR_FRAME, model).body(), motor_joints,
        diff_ik.get_desired_state_output_port() if kinematic else None, couplers)
    if command == "pose":
        # Signed nearer the hand's start orientation (PoseStateFromPlant).
        frame_H = plant.GetFrameByName(HAND_FRAME, model)
        q_start = pose_at(plant, frame_H, q0).rotation().ToQuaternion().wxyz()
        hand_pose = builder.AddNamedSystem("hand_pose", PoseStateFromPlant(plant, frame_H,
                                                                           q_start))
        builder.Connect(state, hand_pose.get_plant_state_input_port())
        builder.ExportOutput(hand_pose.get_hand_pose_output_port(), "hand_pose")
    builder.ExportOutput(state, "state")
    builder.ExportOutput(diff_ik.get_desired_state_output_port(), "desired_state")
    if not kinematic:
        builder.ExportOutput(plant.get_body_poses_output_port(), "body_poses")
    return finish_station(builder, plant, scene_graph, model, config, meshcat, "hsr_station")


hsr_station_plant = station_plant
hsr_initial_ee_state = initial_ee_state


def _ready_frame_pose(config, frame_name):
    """The world pose of the model's frame `frame_name` where a station of `config` starts,
    from the model's kinematics alone (no station)."""
    validate_hsr_station_config(config)
    plant = MultibodyPlant(config.plant.time_step)
    model = add_hsr(plant)
    plant.Finalize()
    return _ready_pose(plant, model, config, frame_name)[1]


def hsr_ready_ee_state(config: HsrStationConfig) -> np.ndarray:
    """The hand's ``ee_state`` (``EeState``) where a station of ``config`` starts, from the
    model's kinematics alone (no station); equal to ``hsr_initial_ee_state`` of it."""
    return ee_state_at_rest(_ready_frame_pose(config, END_EFFECTOR_FRAME))


def hsr_ready_palm_position(config: HsrStationConfig) -> np.ndarray:
    """Where the palm (``hand_palm_link``) of a pose station of ``config`` starts (m), from
    the model's kinematics alone; equal to ``hsr_initial_hand_pose(station)[:3]``."""
    return _ready_frame_pose(config, HAND_FRAME).translation()


def hsr_initial_hand_pose(station: Diagram) -> np.ndarray:
    """The hand's ``hand_pose`` (``PoseState``) where a pose station (``make_hsr_station(
    ..., command="pose")``) starts, at rest: holding its first 7 entries (and a zero
    twist) as ``pose_command`` keeps the robot still."""
    port = checked_station(station).GetOutputPort("hand_pose")
    return np.array(port.Eval(station.CreateDefaultContext()))
