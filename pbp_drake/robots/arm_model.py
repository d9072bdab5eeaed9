"""Loading a fixed-base arm from a URDF or SDFormat file into a MultibodyPlant, with the
checks a user's own model needs: the file (`pbp_drake.robots.model_checks`), the frames,
the chain from the base to the end effector, the joints' limits, the ready configuration
and, for dynamic motion, its mass matrix there; each refusal is a one-line ValueError
naming the `ArmStationConfig` field at fault.
"""

import dataclasses
from pathlib import Path

import numpy as np
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.parsing import Parser
from pydrake.solvers import Solve

from pbp_drake.robots.arm_station_config import DRIVERS
from pbp_drake.robots.hsr_model import configure_parser
from pbp_drake.robots.model_checks import check_model_file, escaped, printable

# The ready configuration's ee_frame z axis must be at most this far (degrees) off the
# floor plane: the heading is where that axis points in it.
MAX_TILT_DEGREES = 60.0


@dataclasses.dataclass(frozen=True)
class ArmModel:
    """An arm loaded into a plant by `add_arm`: its model instance, `base_frame` and
    `ee_frame` (Drake frames), the movable `joints` of the model (in its order; each
    gets a motor) and the `chain` of joints from the base to the end effector."""

    model: object
    base_frame: object
    ee_frame: object
    joints: tuple
    chain: tuple


def add_arm(plant, config):
    """Adds the arm of `config` (an `ArmStationConfig`) to `plant` (not finalized yet),
    its base frame welded to the world at `config.base_pose`, and returns an `ArmModel`.
    Raises ValueError naming the field for a file that is missing or does not parse, a
    frame the model has not, an end effector that is not downstream of the base, a joint
    without limits or of a kind the station cannot move."""
    check_model_file(config.model_file, config.motion)
    parser = Parser(plant)
    configure_parser(parser)
    source = config.model_file
    try:
        if "://" in source:
            models = parser.AddModels(url=source)
        else:
            models = parser.AddModels(str(Path(source)))
    except Exception as error:  # Drake's parser raises RuntimeError with the details
        first = str(error).strip().splitlines()[0] if str(error).strip() else type(error)
        raise ValueError(f"ArmStationConfig.model_file {printable(source)} does not load: "
                         f"{escaped(str(first))}") from None
    if len(models) != 1:
        raise ValueError(f"ArmStationConfig.model_file {source!r} holds {len(models)} models; "
                         "the station takes one arm")
    (model,) = models
    base_frame = _frame(plant, model, config, "base_frame")
    ee_frame = _frame(plant, model, config, "ee_frame")
    inboard = {int(plant.get_joint(index).child_body().index()): plant.get_joint(index)
               for index in plant.GetJointIndices(model)}
    base_body = base_frame.body()
    if int(base_body.index()) in inboard:
        joint = inboard[int(base_body.index())]
        if joint.parent_body().index() == plant.world_body().index():
            raise ValueError(f"ArmStationConfig.base_frame {config.base_frame!r} is fixed to "
                             f"the world by the model itself (joint {joint.name()!r}); remove "
                             "that joint (and the world link) from the model file: the "
                             "station welds base_frame to the world at base_pose")
        raise ValueError(f"ArmStationConfig.base_frame {config.base_frame!r} is not the "
                         f"model's root: it hangs from joint {joint.name()!r} of "
                         f"{joint.parent_body().name()!r}; name the link the arm stands on")
    chain, body = [], ee_frame.body()
    while body.index() != base_body.index():
        if int(body.index()) not in inboard or len(chain) > len(inboard):
            raise ValueError(f"ArmStationConfig.ee_frame {config.ee_frame!r} is not "
                             f"downstream of base_frame {config.base_frame!r}: its chain "
                             f"ends at {body.name()!r}")
        joint = inboard[int(body.index())]
        chain.append(joint)
        body = joint.parent_body()
    chain.reverse()
    joints = [plant.get_joint(index) for index in plant.GetJointIndices(model)
              if plant.get_joint(index).num_velocities() > 0]
    for joint in joints:
        _check_joint(joint, config)
    if config.hardware is not None:
        count = DRIVERS[config.hardware.driver].joint_count
        if len(joints) != count:
            raise ValueError(f"ArmStationConfig.hardware.driver {config.hardware.driver!r} "
                             f"drives {count} joints; the model has {len(joints)}")
    if not any(joint.num_velocities() for joint in chain):
        raise ValueError(f"ArmStationConfig.ee_frame {config.ee_frame!r} is not on the arm: "
                         f"no joint moves it relative to base_frame {config.base_frame!r}")
    x, y, z, yaw = config.base_pose
    plant.WeldFrames(plant.world_frame(), base_frame,
                     RigidTransform(RollPitchYaw(0.0, 0.0, yaw), [x, y, z]))
    return ArmModel(model=model, base_frame=base_frame, ee_frame=ee_frame,
                    joints=tuple(joints), chain=tuple(chain))


def _frame(plant, model, config, field):
    name = getattr(config, field)
    if plant.HasFrameNamed(name, model):
        return plant.GetFrameByName(name, model)
    bodies = [plant.get_body(index).name() for index in plant.GetBodyIndices(model)]
    shown = ", ".join(bodies[:12]) + (", ..." if len(bodies) > 12 else "")
    world = ("; the world is not the model's: name one of its links"
             if name == plant.world_frame().name() else "")
    raise ValueError(f"ArmStationConfig.{field} {name!r} is not a frame of "
                     f"{config.model_file!r} (its links: {shown}){world}")


def _check_joint(joint, config):
    """A joint the station can move: one degree of freedom with finite position and
    velocity limits, and acceleration limits (if any) with room between them."""
    where = f"ArmStationConfig.model_file {config.model_file!r}: joint {joint.name()!r}"
    if joint.num_positions() != 1 or joint.num_velocities() != 1:
        raise ValueError(f"{where} is a {joint.type_name()} joint; the station moves "
                         "revolute and prismatic joints only")
    for kind, lower, upper in (
            ("position", joint.position_lower_limits(), joint.position_upper_limits()),
            ("velocity", joint.velocity_lower_limits(), joint.velocity_upper_limits())):
        if not (np.isfinite(lower).all() and np.isfinite(upper).all()):
            raise ValueError(f"{where} has no {kind} limits; give them in the model (URDF "
                             "<limit lower upper velocity>, SDFormat <limit>)")
        if not (lower < upper).all():
            raise ValueError(f"{where} has {kind} limits [{lower[0]}, {upper[0]}] with no "
                             "room between them; give the joint room to move in the model "
                             "(URDF <limit lower upper velocity>, SDFormat <limit>)")
    # The model's acceleration limits bound the diff IK's; none (infinite) is the default's.
    lower, upper = joint.acceleration_lower_limits(), joint.acceleration_upper_limits()
    if np.isfinite(lower).all() and np.isfinite(upper).all() and not (lower < upper).all():
        raise ValueError(f"{where} has an acceleration limit of "
                         f"{min(-lower[0], upper[0]):g}: it could never move; give a "
                         "positive drake:acceleration in the model, or none (then "
                         "ArmStationConfig.default_acceleration_limit)")


def ready_positions(plant, arm, config):
    """The plant's positions in the ready configuration: `config.initial_positions` (one
    per movable joint of the model, in its order) or the model's defaults, or with
    `config.ready_tool_pose` the inverse kinematics' solution. Raises ValueError for a
    wrong count, a joint outside its limits, a tool pose out of reach, or an ee_frame
    whose z axis is more than MAX_TILT_DEGREES off the floor plane there."""
    q0 = plant.GetDefaultPositions()
    if len(config.initial_positions):
        if len(config.initial_positions) != len(arm.joints):
            names = [joint.name() for joint in arm.joints]
            raise ValueError(f"ArmStationConfig.initial_positions has "
                             f"{len(config.initial_positions)} entries; the arm has "
                             f"{len(arm.joints)} joints {names}")
        for joint, value in zip(arm.joints, config.initial_positions):
            q0[joint.position_start()] = value
    if config.ready_tool_pose is not None:
        q0 = _solve_tool_pose(plant, arm, config, q0)
    for joint in arm.joints:
        value = q0[joint.position_start()]
        lower, upper = joint.position_lower_limits()[0], joint.position_upper_limits()[0]
        if not lower <= value <= upper:
            raise ValueError(f"ArmStationConfig.initial_positions: joint {joint.name()!r} at "
                             f"{value:g} is outside its limits [{lower:g}, {upper:g}]")
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, q0)
    if config.motion == "dynamic":
        _check_mass_matrix(plant, arm, context, config)
    z_axis = arm.ee_frame.CalcPoseInWorld(context).rotation().matrix()[:, 2]
    tilt = np.degrees(np.arcsin(np.clip(abs(z_axis[2]), 0.0, 1.0)))
    if tilt > MAX_TILT_DEGREES:
        raise ValueError(f"ArmStationConfig.initial_positions: ee_frame "
                         f"{config.ee_frame!r}'s z axis is {tilt:.0f} degrees off the floor "
                         f"plane in the ready configuration (at most {MAX_TILT_DEGREES:g}): "
                         "the hand's heading is where that axis points")
    return q0


# Inverse kinematics of the ready tool pose: its tolerances (m, rad), and how many starts
# it tries (the given configuration or the middle of the limits first, then seeded draws).
TOOL_POSITION_TOLERANCE = 1e-5
TOOL_ANGLE_TOLERANCE = 1e-4
IK_STARTS = 40


def _solve_tool_pose(plant, arm, config, q_given):
    """The configuration within the joints' limits that puts ee_frame at
    `config.ready_tool_pose`, nearest `q_given` (`config.initial_positions`) or else the
    middle of the limits, solved from it and from seeded starts, the least cost kept
    (deterministic; remembered per model and pose)."""
    X_WE = config.ready_tool_pose.transform()
    lower, upper = plant.GetPositionLowerLimits(), plant.GetPositionUpperLimits()
    nominal = np.asarray(q_given if len(config.initial_positions) else (lower + upper) / 2, float)
    key = (config.model_file, config.base_frame, config.ee_frame, tuple(config.base_pose),
           tuple(config.ready_tool_pose.position), tuple(config.ready_tool_pose.rpy_degrees),
           tuple(nominal))
    if key in _SOLVED_TOOL_POSES:
        return _SOLVED_TOOL_POSES[key].copy()
    starts = np.random.default_rng(0).uniform(0.1, 0.9, (IK_STARTS, len(nominal)))
    best, p = None, X_WE.translation()
    for start in [nominal, *(lower + (upper - lower) * starts)]:
        ik = InverseKinematics(plant)
        q = ik.q()
        ik.AddPositionConstraint(arm.ee_frame, np.zeros(3), plant.world_frame(),
                                 p - TOOL_POSITION_TOLERANCE, p + TOOL_POSITION_TOLERANCE)
        ik.AddOrientationConstraint(plant.world_frame(), X_WE.rotation(), arm.ee_frame,
                                    RotationMatrix(), TOOL_ANGLE_TOLERANCE)
        program = ik.get_mutable_prog()
        program.AddQuadraticErrorCost(np.eye(len(nominal)), nominal, q)
        program.SetInitialGuess(q, start)
        result = Solve(program)
        if result.is_success() and (best is None or result.get_optimal_cost() < best[0]):
            best = (result.get_optimal_cost(), np.clip(result.GetSolution(q), lower, upper))
    if best is None:
        shown = ", ".join(f"{value:g}" for value in p)
        raise ValueError(f"ArmStationConfig.ready_tool_pose: ee_frame {config.ee_frame!r} "
                         f"cannot stand at [{shown}] m in that orientation within the joints' "
                         f"limits (inverse kinematics from {IK_STARTS + 1} starts)")
    _SOLVED_TOOL_POSES[key] = best[1]
    return best[1].copy()


_SOLVED_TOOL_POSES = {}


# The mass matrix is singular (a joint whose motion moves no inertia) when its smallest
# eigenvalue is this small against its largest: Drake's dynamics then fail mid-run.
SINGULAR_MASS_MATRIX = 1e-10


def _check_mass_matrix(plant, arm, context, config):
    """Dynamic motion steps the plant: its mass matrix must be positive-definite (the file's
    checks refuse a joint that moves no mass; this one, a joint that turns no inertia)."""
    mass_matrix = plant.CalcMassMatrix(context)
    moments, directions = np.linalg.eigh(mass_matrix)
    if moments[0] > SINGULAR_MASS_MATRIX * max(moments[-1], 1e-300):
        return
    velocity = int(np.argmax(np.abs(directions[:, 0])))
    joint = next(joint for joint in arm.joints if joint.velocity_start() == velocity)
    raise ValueError(f"ArmStationConfig.model_file {printable(config.model_file)}: joint "
                     f"{printable(joint.name())} moves no inertia about its axis (the mass "
                     f"matrix is singular in the ready configuration): link "
                     f"{printable(joint.child_body().name())} and what hangs from it need "
                     "mass and inertia <inertial> that the joint turns; motion: dynamic "
                     "needs them (or use motion: kinematic)")


def reach_of(plant, arm, q0):
    """`arm_reach`'s `(shoulder, reach)`, measured in the ready configuration `q0` (the
    reach: the chain's joint origins' distances summed, each the longest a prismatic joint
    between them makes it within its limits, and a first joint's travel if prismatic)."""
    moving = [joint for joint in arm.chain if joint.num_velocities()]
    # A prismatic joint changes the distance from the joint before it to its own origin
    # (a telescope retracted in the ready configuration), longest at one of its limits.
    configurations = [q0]
    for joint in moving:
        if joint.type_name() == "prismatic":
            for limit in (joint.position_lower_limits(), joint.position_upper_limits()):
                q = np.array(q0, dtype=float)
                q[joint.position_start()] = limit[0]
                configurations.append(q)
    context = plant.CreateDefaultContext()
    lengths = []
    for q in configurations:
        plant.SetPositions(context, q)
        points = [joint.frame_on_child().CalcPoseInWorld(context).translation()
                  for joint in moving]
        points.append(arm.ee_frame.CalcPoseInWorld(context).translation())
        if q is q0:
            shoulder = points[0]
        lengths.append([np.linalg.norm(b - a) for a, b in zip(points, points[1:])])
    reach = float(sum(max(segment) for segment in zip(*lengths)))
    if moving and moving[0].type_name() == "prismatic":  # it moves the shoulder itself
        q = q0[moving[0].position_start()]
        reach += float(max(moving[0].position_upper_limits()[0] - q,
                           q - moving[0].position_lower_limits()[0]))
    return shoulder, reach
