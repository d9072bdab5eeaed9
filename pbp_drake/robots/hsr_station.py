"""A simulated HSR that follows an end-effector command: plant, whole-body diff IK, PD.

``add_hsr_station`` adds to a DiagramBuilder everything between an operator's (or a
policy's) end-effector command and the robot's motion::

    ee_command ─► EeCommandToPose ─► DifferentialInverseKinematicsIntegrator ─► q_d
    q_d ─► DiscreteDerivative ─► v_d
    [q_d, v_d] ─► arm: the plant's PD-controlled actuators (desired_state input)
               └► base: PD as one MatrixGain on [desired, state] ─► applied_generalized_force
    plant ─► EeStateFromPlant ─► ee_state

Gravity is off, which stands for the ideal gravity compensation of the real robot's
controllers; nothing else compensates it. The base and the arm are solved together by
one differential IK, so a target out of the arm's reach moves the base.

Example::

    builder = DiagramBuilder()
    station = add_hsr_station(builder)
    command = builder.AddSystem(ConstantVectorSource(station.initial_ee_state[:7]))
    builder.Connect(command.get_output_port(), station.ee_command)
    builder.ExportOutput(station.ee_state, "ee_state")
    diagram = builder.Build()
"""

import dataclasses
from dataclasses import dataclass

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import MeshcatVisualizer, MeshcatVisualizerParams, Role
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.inverse_kinematics import (
    DifferentialInverseKinematicsIntegrator,
    DifferentialInverseKinematicsParameters,
)
from pydrake.multibody.math import SpatialVelocity
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlantConfig
from pydrake.multibody.tree import ModelInstanceIndex, PdControllerGains
from pydrake.systems.framework import LeafSystem
from pydrake.systems.primitives import DiscreteDerivative, MatrixGain, Multiplexer

from pbp_drake.robots.hsr_model import (
    ARM_JOINT_NAMES,
    BASE_JOINT_NAME,
    END_EFFECTOR_FRAME,
    TORSO_JOINT_NAME,
    TORSO_TO_ARM_LIFT_RATIO,
    add_hsr,
)

# Ready pose: the arm leans forward by READY_ARM_FLEX and the wrist levels the hand, so
# the hand starts in front of the base with room to move both ways along x with the
# arm alone; arm_lift then sets the height.
READY_ARM_FLEX = -0.5
# PD gains of the arm actuators (arm_lift in N/m and N·s/m, the others in N·m/rad and
# N·m·s/rad). The plant applies them implicitly, so high gains stay stable.
ARM_KP = (2000.0, 1000.0, 500.0, 300.0, 300.0)
ARM_KD = (200.0, 100.0, 50.0, 30.0, 30.0)
# How far the robot lags behind the pose it tracks (s): about one diff-IK step and the PD.
TRACKING_LAG = 0.005
# Base PD (x, y in N/m, N·s/m; yaw in N·m/rad, N·m·s/rad). These forces are explicit (one
# time step behind), so damping stays well below mass / time_step (35 kg, ~3 kg·m²).
BASE_KP = (8000.0, 8000.0, 1500.0)
BASE_KD = (1200.0, 1200.0, 200.0)
# How fast the redundant joints drift back to the ready pose (1/s) inside the diff-IK
# null space; the base has no centering, so it takes over what the arm held.
ARM_CENTERING_GAIN = 1.0


@dataclass
class HsrStation:
    """What ``add_hsr_station`` added; the ports belong to systems inside the builder.

    Attributes:
        plant: the discrete MultibodyPlant (gravity off) holding the HSR.
        scene_graph: its SceneGraph, e.g. for distance queries against obstacles.
        model: the HSR's model instance.
        diff_ik: the whole-body DifferentialInverseKinematicsIntegrator (its parameters
            can be changed before simulating, e.g. to add velocity constraints).
        ee_command: input (7) ``[p_WE (3), v_WE (3), heading]``.
        ee_state: output (8) ``[p_WE (3), v_WE (3), heading, heading_rate]``.
        initial_ee_state: ``ee_state`` at the initial (default) configuration.
        visualizer: the MeshcatVisualizer, if a Meshcat was given.
    """

    plant: object
    scene_graph: object
    model: ModelInstanceIndex
    diff_ik: DifferentialInverseKinematicsIntegrator
    ee_command: object
    ee_state: object
    initial_ee_state: np.ndarray
    visualizer: MeshcatVisualizer | None = None


@dataclass
class HsrStationConfig:
    """TEMPORARY (replaced by the station branch)."""

    plant: MultibodyPlantConfig = dataclasses.field(default_factory=lambda: MultibodyPlantConfig(
        time_step=0.005, discrete_contact_approximation="sap"))
    diff_ik_time_step: float = 0.01
    command_period: float = 0.0
    initial_base: list[float] = dataclasses.field(default_factory=lambda: [0.0, 0.0, 0.0])
    ee_height: float = 0.7


def hsr_initial_ee_state(config):
    """TEMPORARY."""
    from pydrake.systems.framework import DiagramBuilder
    station = add_hsr_station(DiagramBuilder(), config.plant.time_step,
                              initial_base=config.initial_base, ee_height=config.ee_height)
    return station.initial_ee_state


def heading_of(R_WE: RotationMatrix) -> float:
    """The direction the hand points in the floor plane: atan2 of its z axis' (x, y)."""
    z_axis = R_WE.matrix()[:, 2]
    return float(np.arctan2(z_axis[1], z_axis[0]))


class EeCommandToPose(LeafSystem):
    """Turns the 7-vector end-effector command into the desired pose for diff IK.

    .. pydrake_system::

        name: EeCommandToPose
        input_ports:
        - ee_command
        output_ports:
        - X_WE_desired

    `ee_command` is `[p (3), v (3), heading]`; the pose is `(Rz(heading) R_E0, p)` where
    `R_E0` is the hand pointing along world +x.

    With a `command_period` (a control loop that sends, at each tick, the state to be in at
    the next tick), the position ramps into `p` at velocity `v`: `p - v (t_next - t - lead)`.
    Tracking `p` as a step once a tick would leave the robot behind by most of a tick's
    travel, and a policy re-integrated from the robot's state (PBP) would then run slow.
    `lead` makes up for the lag of differential IK and PD behind the pose they track.
    """

    def __init__(self, R_E0: RotationMatrix, command_period=None, lead=0.0):
        super().__init__()
        self._R_E0 = RotationMatrix(R_E0)
        self._period = command_period
        self._lead = float(lead)
        self._command_port = self.DeclareVectorInputPort("ee_command", 7)
        self._pose_port = self.DeclareAbstractOutputPort(
            "X_WE_desired", lambda: AbstractValue.Make(RigidTransform()), self._calc_pose)

    def get_ee_command_input_port(self):
        return self._command_port

    def get_pose_output_port(self):
        return self._pose_port

    def _calc_pose(self, context, output):
        command = self._command_port.Eval(context)
        R = RotationMatrix.MakeZRotation(command[6]) @ self._R_E0
        position = command[:3]
        if self._period:
            time = context.get_time()
            next_tick = np.ceil(time / self._period - 1e-9) * self._period
            position = position - command[3:6] * (max(0.0, next_tick - time) - self._lead)
        output.set_value(RigidTransform(R, position))


class EeStateFromPlant(LeafSystem):
    """Reads the end effector's position, velocity and heading off the plant's outputs.

    .. pydrake_system::

        name: EeStateFromPlant
        input_ports:
        - body_poses
        - body_spatial_velocities
        output_ports:
        - ee_state

    `ee_state` is `[p_WE (3), v_WE (3), heading, heading_rate]`; heading_rate is the
    hand's angular velocity about world z (the rate of the heading while the hand's z
    axis stays near the floor plane).
    """

    def __init__(self, ee_body_index):
        super().__init__()
        self._index = int(ee_body_index)
        self._poses_port = self.DeclareAbstractInputPort(
            "body_poses", AbstractValue.Make([RigidTransform()]))
        self._velocities_port = self.DeclareAbstractInputPort(
            "body_spatial_velocities", AbstractValue.Make([SpatialVelocity()]))
        self._state_port = self.DeclareVectorOutputPort("ee_state", 8, self._calc_state)

    def get_body_poses_input_port(self):
        return self._poses_port

    def get_body_spatial_velocities_input_port(self):
        return self._velocities_port

    def get_ee_state_output_port(self):
        return self._state_port

    def _calc_state(self, context, output):
        X_WE = self._poses_port.Eval(context)[self._index]
        V_WE = self._velocities_port.Eval(context)[self._index]
        w, v = V_WE.rotational(), V_WE.translational()
        output.SetFromVector(np.concatenate(
            [X_WE.translation(), v, [heading_of(X_WE.rotation()), w[2]]]))


def base_pd_gain(plant, base_joint, kp, kd):
    """The matrix `G` (nv, 2 (nq + nv)) of PD forces on the unactuated planar base:
    `G [desired_state; state]` is `kp (q_d - q) + kd (v_d - v)` on the base's (x, y, yaw)
    generalized forces and zero elsewhere. Applied by a MatrixGain (in C++: a Python
    system here would run at every plant step)."""
    nq, nv = plant.num_positions(), plant.num_velocities()
    nx = nq + nv
    gain = np.zeros((nv, 2 * nx))
    for axis, (p_gain, d_gain) in enumerate(zip(kp, kd)):
        force = base_joint.velocity_start() + axis
        q = base_joint.position_start() + axis
        v = nq + base_joint.velocity_start() + axis
        gain[force, q], gain[force, nx + q] = p_gain, -p_gain
        gain[force, v], gain[force, nx + v] = d_gain, -d_gain
    return gain


def ready_positions(plant, model, initial_base=(0.0, 0.0, 0.0), ee_height=0.7):
    """Plant positions with the base at ``initial_base`` and the hand level and pointing
    along the base's +x at height ``ee_height`` in front of the base.

    Solved analytically: the flex and wrist flex joints both turn about the arm's -y,
    so a wrist flex of ``-pi/2 - arm_flex`` levels the hand; the lift then adds height
    one to one.
    """
    context = plant.CreateDefaultContext()
    plant.GetJointByName(BASE_JOINT_NAME, model).set_pose(
        context, initial_base[:2], initial_base[2])
    plant.GetJointByName("arm_flex_joint", model).set_angle(context, READY_ARM_FLEX)
    plant.GetJointByName("wrist_flex_joint", model).set_angle(
        context, -np.pi / 2 - READY_ARM_FLEX)
    ee = plant.GetFrameByName(END_EFFECTOR_FRAME, model)
    arm_lift = plant.GetJointByName("arm_lift_joint", model)
    lift = ee_height - ee.CalcPoseInWorld(context).translation()[2]
    if not arm_lift.position_lower_limits()[0] <= lift <= arm_lift.position_upper_limits()[0]:
        raise ValueError(f"ee_height {ee_height} m is out of the arm lift's range")
    arm_lift.set_translation(context, lift)
    # Keep the torso coupler satisfied from the start, or SAP would snap it at t = 0.
    plant.GetJointByName(TORSO_JOINT_NAME, model).set_translation(
        context, TORSO_TO_ARM_LIFT_RATIO * lift)
    return plant.GetPositions(context)


def _make_diff_ik(plant, model, q0, time_step):
    ee = plant.GetFrameByName(END_EFFECTOR_FRAME, model)
    nq = plant.num_positions()
    params = DifferentialInverseKinematicsParameters(nq, plant.num_velocities())
    params.set_joint_position_limits(
        (plant.GetPositionLowerLimits(), plant.GetPositionUpperLimits()))
    v_lower, v_upper = plant.GetVelocityLowerLimits(), plant.GetVelocityUpperLimits()
    # The torso does not move the hand (it carries only the head) and follows the lift
    # through the coupler in the plant, so diff IK leaves it where it is.
    torso = plant.GetJointByName(TORSO_JOINT_NAME, model).velocity_start()
    v_lower[torso] = v_upper[torso] = 0.0
    params.set_joint_velocity_limits((v_lower, v_upper))
    params.set_nominal_joint_position(q0)
    centering = np.zeros(nq)
    for name in ARM_JOINT_NAMES:
        centering[plant.GetJointByName(name, model).position_start()] = ARM_CENTERING_GAIN
    params.set_joint_centering_gain(np.diag(centering))
    return DifferentialInverseKinematicsIntegrator(
        plant, ee, time_step, params, log_only_when_result_state_changes=True)


def add_hsr_station(builder, time_step=0.005, meshcat=None, initial_base=(0.0, 0.0, 0.0),
                    ee_height=0.7, diff_ik_time_step=None, command_period=None) -> HsrStation:
    """Adds the HSR, its whole-body end-effector controller and (optionally) a
    visualizer to ``builder``.

    Args:
        builder: a DiagramBuilder; the caller connects ``ee_command`` and reads
            ``ee_state`` (or exports them).
        time_step: the plant's discrete time step (s).
        meshcat: if given, a MeshcatVisualizer draws the robot's illustration geometry.
        initial_base: the base's (x, y, yaw) at the start.
        ee_height: the hand's height at the start (m); it starts level, pointing along
            the base's +x in front of the base.
        diff_ik_time_step: period of the diff-IK integrator (s), ``time_step`` by
            default; a multiple of ``time_step`` costs fewer QP solves.
        command_period: the period of a control loop that sends each tick the state
            ``[p, v]`` to reach at the next tick; the station then ramps into ``p`` at
            ``v`` (see EeCommandToPose). None: track ``p`` as given.

    Returns:
        An HsrStation. A fresh context starts at rest in the ready pose with the diff
        IK already there, so holding ``initial_ee_state[:7]`` keeps the robot still.
    """
    diff_ik_time_step = diff_ik_time_step or time_step
    plant, scene_graph = AddMultibodyPlant(
        MultibodyPlantConfig(time_step=time_step, discrete_contact_approximation="sap"),
        builder)
    model = add_hsr(plant)
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
    for name, kp, kd in zip(ARM_JOINT_NAMES, ARM_KP, ARM_KD):
        # The URDF transmissions name each motor after its joint.
        actuator = plant.GetJointActuatorByName(name.replace("_joint", "_motor"), model)
        actuator.set_controller_gains(PdControllerGains(p=kp, d=kd))
    plant.Finalize()

    q0 = ready_positions(plant, model, initial_base, ee_height)
    plant.SetDefaultPositions(q0)
    context = plant.CreateDefaultContext()
    X_WE0 = plant.GetFrameByName(END_EFFECTOR_FRAME, model).CalcPoseInWorld(context)
    heading0 = heading_of(X_WE0.rotation())
    # R_E0 is the hand's orientation at heading 0, whatever the initial base yaw.
    R_E0 = RotationMatrix.MakeZRotation(-heading0) @ X_WE0.rotation()
    initial_ee_state = np.concatenate([X_WE0.translation(), np.zeros(3), [heading0, 0.0]])

    command_to_pose = builder.AddNamedSystem(
        "ee_command_to_pose", EeCommandToPose(R_E0, command_period, lead=TRACKING_LAG))
    diff_ik = builder.AddNamedSystem(
        "diff_ik", _make_diff_ik(plant, model, q0, diff_ik_time_step))
    builder.Connect(command_to_pose.get_pose_output_port(),
                    diff_ik.GetInputPort("X_AE_desired"))
    # Connected only so that the integrator's initialization event starts it from the
    # plant's state (no jump even if the caller moves the robot in the context); with
    # use_robot_state unconnected it then integrates its own state, which is stable.
    builder.Connect(plant.get_state_output_port(), diff_ik.GetInputPort("robot_state"))

    nq, nv = plant.num_positions(), plant.num_velocities()
    velocity = builder.AddNamedSystem(
        "diff_ik_velocity", DiscreteDerivative(nq, diff_ik_time_step))
    builder.Connect(diff_ik.get_output_port(), velocity.get_input_port())
    desired = builder.AddNamedSystem("desired_state", Multiplexer([nq, nv]))
    builder.Connect(diff_ik.get_output_port(), desired.get_input_port(0))
    builder.Connect(velocity.get_output_port(), desired.get_input_port(1))

    # Arm: the plant's own PD on the actuated joints, in actuator order.
    actuated = [plant.get_joint_actuator(i).joint().index()
                for i in plant.GetJointActuatorIndices(model)]
    arm_selector = builder.AddNamedSystem(
        "arm_desired_state", MatrixGain(plant.MakeStateSelectorMatrix(actuated)))
    builder.Connect(desired.get_output_port(), arm_selector.get_input_port())
    builder.Connect(arm_selector.get_output_port(), plant.get_desired_state_input_port(model))

    base_pd_input = builder.AddNamedSystem("base_pd_input", Multiplexer([nq + nv, nq + nv]))
    builder.Connect(desired.get_output_port(), base_pd_input.get_input_port(0))
    builder.Connect(plant.get_state_output_port(), base_pd_input.get_input_port(1))
    base_pd = builder.AddNamedSystem("base_pd", MatrixGain(base_pd_gain(
        plant, plant.GetJointByName(BASE_JOINT_NAME, model), BASE_KP, BASE_KD)))
    builder.Connect(base_pd_input.get_output_port(), base_pd.get_input_port())
    builder.Connect(base_pd.get_output_port(),
                    plant.get_applied_generalized_force_input_port())

    ee_body = plant.GetFrameByName(END_EFFECTOR_FRAME, model).body()
    ee_state = builder.AddNamedSystem("ee_state", EeStateFromPlant(ee_body.index()))
    builder.Connect(plant.get_body_poses_output_port(), ee_state.get_body_poses_input_port())
    builder.Connect(plant.get_body_spatial_velocities_output_port(),
                    ee_state.get_body_spatial_velocities_input_port())

    visualizer = None
    if meshcat is not None:
        visualizer = MeshcatVisualizer.AddToBuilder(
            builder, scene_graph, meshcat, MeshcatVisualizerParams(role=Role.kIllustration))

    return HsrStation(
        plant=plant, scene_graph=scene_graph, model=model, diff_ik=diff_ik,
        ee_command=command_to_pose.get_ee_command_input_port(),
        ee_state=ee_state.get_ee_state_output_port(),
        initial_ee_state=initial_ee_state, visualizer=visualizer)
