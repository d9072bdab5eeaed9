"""A fixed-base arm from any URDF or SDFormat file that follows an end-effector command, as
one Diagram with the HSR station's ports (docs/concepts/your-robot.md has an example)::

    ee_command ─► WholeBodyDiffIk (its EeCommandRamp) ─► [q_d, v_d] (desired_state)
    desired_state ─► KinematicJoints (motion: kinematic) or the plant's PD (dynamic)
    robot state ─► EeStateFromPlant (ee_frame) ─► ee_state
    obstacle_positions ─► CylinderObstacleGeometry ─► SceneGraph ─► CollisionMonitor

With ``config.hardware.connect`` the same ports drive a real arm through its Drake LCM
driver, ``DriverLink``'s measured state in place of the plan (docs/tasks/real-arm.md, "What
the station does"); with ``hardware.driver_sim`` the driver simulator inside, on a memq://
bus of its own. The diff IK is the HSR station's; gravity is off.
"""

import numpy as np
from pydrake.lcm import DrakeLcm
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import PdControllerGains
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.lcm import LcmInterfaceSystem, LcmSubscriberSystem

from pbp_drake.robots.arm_driver import (
    SIMULATION_CLOCK, WALL_CLOCK, DriverLink, read_first_status, status_type)
from pbp_drake.robots.arm_model import add_arm, reach_of, ready_positions
from pbp_drake.robots.arm_station_config import (
    DRIVERS, ArmStationConfig, check_config_type, validate_arm_station_config)
from pbp_drake.robots.driver_sim import make_driver_sim
from pbp_drake.robots.hsr_diff_ik import WholeBodyDiffIk
from pbp_drake.robots.hsr_ee_systems import ee_state_at_rest, station_ramp
from pbp_drake.robots.station_parts import (
    add_robot, add_station_plant, finish_station, initial_ee_state, pose_at, station_plant)


def make_arm_station(config: ArmStationConfig, meshcat=None) -> Diagram:
    """The arm of `config`, its end-effector controller, and optionally obstacles and a
    Meshcat visualizer, as one Diagram named ``arm_station``.

    .. pydrake_system::

        name: arm_station
        input_ports:
        - ee_command
        - obstacle_positions (with config.obstacles)
        output_ports:
        - ee_state
        - state
        - desired_state
        - query_object
        - in_collision (with config.obstacles)
        - clearance (with config.obstacles)

    The ports are ``make_hsr_station``'s, of ``ee_frame`` (its orientation the ready one
    turned about the vertical by the heading), ``desired_state`` over every joint of the
    model in its order. A fresh context starts at rest in the ready configuration. Raises
    ValueError naming the config's field that cannot work.
    """
    validate_arm_station_config(config)
    builder = DiagramBuilder()
    hardware = config.hardware if config.hardware is not None and config.hardware.connect \
        else None
    kinematic = config.motion == "kinematic" or hardware is not None
    plant, scene_graph = add_station_plant(builder, config, kinematic)
    arm = add_arm(plant, config)
    if not kinematic:
        _add_motors(plant, arm)
    plant.Finalize()
    q0 = ready_positions(plant, arm, config)
    plant.SetDefaultPositions(q0)
    if not kinematic:
        _set_servo_gains(plant, arm, q0, config.servo_frequency)
    ramp = station_ramp(pose_at(plant, arm.ee_frame, q0), config)
    look_ahead = 0.0 if kinematic else config.plant.time_step
    diff_ik = builder.AddNamedSystem("diff_ik", _make_diff_ik(plant, arm, q0, config, ramp,
                                                              look_ahead))
    joints_input = diff_ik.get_desired_state_output_port() if kinematic else None
    if hardware is not None:
        joints_input = _add_driver_link(builder, plant, arm, q0, hardware, diff_ik)
    state = add_robot(builder, plant, scene_graph, arm.model, diff_ik, ramp, arm.ee_frame,
                      arm.joints, joints_input)
    builder.ExportOutput(state, "state")
    builder.ExportOutput(diff_ik.get_desired_state_output_port(), "desired_state")
    return finish_station(builder, plant, scene_graph, arm.model, config, meshcat,
                          "arm_station")


def _add_driver_link(builder, plant, arm, q0, hardware, diff_ik):
    """The LCM side of the station (docs/tasks/real-arm.md); returns the measured state's
    port. `q0` is where the driver's first status put the arm (or the simulator)."""
    driver = DRIVERS[hardware.driver]
    q_start = _arm_positions(arm, q0)
    lower, upper, velocity = _joint_limits(plant, arm)
    if hardware.driver_sim:
        lcm, clock = DrakeLcm("memq://"), SIMULATION_CLOCK
        builder.AddNamedSystem("driver_sim", make_driver_sim(
            hardware.driver, lcm, clock, q_start, lower, upper, velocity,
            with_interface=False))
    else:
        lcm, clock = DrakeLcm(hardware.lcm_bus), WALL_CLOCK
    builder.AddNamedSystem("lcm", LcmInterfaceSystem(lcm))
    status = builder.AddNamedSystem("status_subscriber", LcmSubscriberSystem.Make(
        driver.status_channel, status_type(hardware.driver), lcm))
    link = builder.AddNamedSystem("driver_link", DriverLink(
        hardware, lcm, q_start, lower, upper, velocity, clock))
    builder.Connect(status.get_output_port(), link.GetInputPort("status"))
    builder.Connect(diff_ik.get_desired_state_output_port(), link.GetInputPort("desired_state"))
    return link.GetOutputPort("state")


def _arm_positions(arm, q):
    """The arm's joints' entries of the plant's positions `q`, in the model's order."""
    return np.array([q[joint.position_start()] for joint in arm.joints])


def _joint_limits(plant, arm):
    """`(lower, upper, velocity)` of the arm's joints, in the model's order."""
    rows = [(joint.position_lower_limits()[0], joint.position_upper_limits()[0],
             joint.velocity_upper_limits()[0]) for joint in arm.joints]
    return tuple(np.array(column) for column in zip(*rows))


def arm_driver_sim(config: ArmStationConfig, lcm, clock=WALL_CLOCK) -> Diagram:
    """The driver simulator of `config`'s arm (`config.hardware.driver`) on `lcm`, standing
    in the ready configuration, with its own `LcmInterfaceSystem`: what `pbp-drake
    driver-sim` runs."""
    _check_hardware(config, "the driver to simulate")
    plant, arm, q0 = arm_model_plant(config)
    return make_driver_sim(config.hardware.driver, lcm, clock, _arm_positions(arm, q0),
                           *_joint_limits(plant, arm))


def _check_hardware(config, what):
    check_config_type(config, ArmStationConfig)
    if config.hardware is None:
        raise ValueError(f"ArmStationConfig.hardware is needed: {what} (hardware: "
                         "{driver: panda} or {driver: iiwa})")


def drives_real_robot(hardware) -> bool:
    """Whether a station of this `ArmHardware` or `TaskSpaceBridgeConfig` (or None) drives
    a real robot: connected, not to the simulator of its driver or relay."""
    return hardware is not None and hardware.connect and not hardware.driver_sim


def measured_ready_positions(config: ArmStationConfig) -> np.ndarray:
    """The arm's joint positions from its driver's first status: the ready configuration of
    a run on the real arm, read before the run is built, on a DrakeLcm of its own on
    `config.hardware.lcm_bus` (its Python callback must not run inside a simulation, which
    newer Drakes advance without Python's lock). Raises `DriverError` naming the bus and
    channel when no status comes within `connect_timeout`."""
    _check_hardware(config, "the driver to read")
    plant, arm, _ = arm_model_plant(config)
    lower, upper, _ = _joint_limits(plant, arm)
    return read_first_status(config.hardware, DrakeLcm(config.hardware.lcm_bus), lower, upper)


def _add_motors(plant, arm):
    """A motor on every joint the model left without one (the plant's PD drives them).
    Before Finalize only the plant-wide list holds the model's own motors."""
    driven = {int(plant.get_joint_actuator(index).joint().index())
              for index in plant.GetJointActuatorIndices()}
    for joint in arm.joints:
        if int(joint.index()) not in driven:
            plant.AddJointActuator(f"{joint.name()}_pbp_motor", joint)


def _set_servo_gains(plant, arm, q0, frequency):
    """Each motor's gains of `ArmStationConfig.servo_frequency`, its joint's inertia the
    mass matrix's diagonal at `q0`."""
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, q0)
    inertia = np.diag(plant.CalcMassMatrix(context))
    for index in plant.GetJointActuatorIndices(arm.model):
        actuator = plant.get_joint_actuator(index)
        joint_inertia = inertia[actuator.joint().velocity_start()]
        actuator.set_controller_gains(PdControllerGains(p=joint_inertia * frequency ** 2,
                                                        d=2.0 * joint_inertia * frequency))


def _make_diff_ik(plant, arm, q0, config, ramp, look_ahead):
    """The diff IK of the end-effector frame within the model's position and velocity
    limits, the acceleration limits the model gives (else the config's default), every
    joint drifting back to `q0` at the config's centering gain."""
    nv = plant.num_velocities()
    accelerations = np.full(nv, np.inf)
    for joint in arm.joints:
        limit = float(min(-joint.acceleration_lower_limits()[0],
                          joint.acceleration_upper_limits()[0]))
        accelerations[joint.velocity_start()] = (
            limit if np.isfinite(limit) and limit > 0 else config.default_acceleration_limit)
    return WholeBodyDiffIk(
        plant, arm.ee_frame, config.diff_ik_time_step, look_ahead, list(arm.joints),
        position_limits=(plant.GetPositionLowerLimits(), plant.GetPositionUpperLimits()),
        velocity_limits=(plant.GetVelocityLowerLimits(), plant.GetVelocityUpperLimits()),
        acceleration_limits=(-accelerations, accelerations), q_nominal=q0,
        centering_gain=np.full(plant.num_positions(), config.centering_gain),
        command_ramp=ramp, singular_margin=config.singular_margin,
        limit_margin=config.limit_margin, brake_at_limits=True)


def arm_model_plant(config: ArmStationConfig):
    """`(plant, arm, q0)`: a finalized bare plant of `config`'s arm (no station), its
    `ArmModel` and ready positions. Raises ValueError as `make_arm_station` does."""
    validate_arm_station_config(config)
    plant = MultibodyPlant(config.plant.time_step)
    arm = add_arm(plant, config)
    plant.Finalize()
    return plant, arm, ready_positions(plant, arm, config)


def arm_ready_ee_state(config: ArmStationConfig) -> np.ndarray:
    """The hand's ``ee_state`` (``EeState``) where a station of ``config`` starts, from the
    model's kinematics alone; equal to ``arm_initial_ee_state`` of that station."""
    return arm_ready_ee_state_and_reach(config)[0]


def arm_reach(config: ArmStationConfig):
    """`(shoulder, reach)` of `config`'s arm: the world position of the first joint that
    moves the end effector and the farthest (m) the end effector can be from it."""
    return arm_ready_ee_state_and_reach(config)[1]


def arm_ready_ee_state_and_reach(config: ArmStationConfig):
    """`(arm_ready_ee_state, arm_reach)` of `config`, from one parse of the model: what a
    scenario is resolved from before its station is built."""
    plant, arm, q0 = arm_model_plant(config)
    return ee_state_at_rest(pose_at(plant, arm.ee_frame, q0)), reach_of(plant, arm, q0)


arm_initial_ee_state = initial_ee_state
arm_station_plant = station_plant
