"""The six-DoF HSR station (``make_hsr_station(command="pose")``): its hand frame
``hand_palm_link`` follows a ``PoseState`` command, turning as well as moving, within the
joints' limits, reaches grasp poses of the grasp task's scenes, and refuses a command that
is not a pose."""

import numpy as np
import pytest
from pydrake.common.eigen_geometry import Quaternion
from pydrake.math import RotationMatrix
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput, ZeroOrderHold

from pbp_drake.core.grasp_task import approach_direction, grasp_success, sample_grasp_scene
from pbp_drake.core.quaternion import angle_between, exp_map, multiply
from pbp_drake.core.grasp_task import side_grasp_orientation
from pbp_drake.robots import HsrStationConfig, hsr_initial_hand_pose, make_hsr_station
from pbp_drake.robots.hsr_model import TORSO_JOINT_NAME, add_hsr
from pbp_drake.systems.ports import PoseState
from pose_drive import PoseWaypoints, drive, turned

# Drives of the pose station (4 s of the fast suite): `make test` runs them.
pytestmark = pytest.mark.slow

POSITION_TOLERANCE = 0.01  # m, after settling
ANGLE_TOLERANCE = np.radians(3.0)
# The grasp task's success bounds (docs/tasks/grasp.md).
SUCCESS_DISTANCE, SUCCESS_ANGLE = 0.03, np.radians(10.0)


@pytest.fixture(scope="module")
def start():
    return hsr_initial_hand_pose(make_hsr_station(command="pose"))


def roll(quaternion, degrees):
    """``quaternion`` turned about the hand's own approach axis z_H."""
    return multiply(quaternion, exp_map(np.radians(degrees) * np.array([0.0, 0.0, 1.0])))


@pytest.fixture(scope="module")
def turns(start):
    """The hand, staying where it is, turns 45 degrees left (yaw), pitches down to point
    straight at the floor (a top grasp) and rolls its wrist by 60 degrees; each is held
    1.5 s. Returns the drive and the times each held pose is checked at."""
    p, q = start[:3], start[3:7]
    yawed = turned([0, 0, 1], 45, q)
    pitched = turned([0, 0, 1], 45, turned([0, 1, 0], 90, q))
    segments = [(0.0, 2.0, p, yawed), (3.5, 2.5, p, pitched), (7.5, 2.0, p, roll(pitched, 60))]
    return drive(segments, 11.0), (3.5, 7.5, 11.0)


def plant_limits():
    """Position and velocity limits of the model's joints, as the plant orders them."""
    plant = MultibodyPlant(0.005)
    model = add_hsr(plant)
    plant.Finalize()
    torso = plant.GetJointByName(TORSO_JOINT_NAME, model).velocity_start()
    return (plant.GetPositionLowerLimits(), plant.GetPositionUpperLimits(),
            plant.GetVelocityUpperLimits(), torso)


def test_the_hand_starts_level_pointing_ahead_with_its_fingers_closing_sideways(start):
    # What a grasp convention must start from: hand_palm_link at the ready pose has its
    # approach axis z_H along +x, x_H straight up and y_H along -y (docs/concepts/six-dof.md).
    R = RotationMatrix(Quaternion(start[3:7])).matrix()  # columns x_H, y_H, z_H
    np.testing.assert_allclose(R, [[0, 0, 1], [0, -1, 0], [1, 0, 0]], atol=1e-9)
    np.testing.assert_allclose(start[:3], [0.4513, 0.078, 0.7], atol=1e-4)
    # The grasp task's side grasp straight ahead is that hand (up to the quaternion's sign).
    assert angle_between(side_grasp_orientation(0.0), start[3:7]) < 1e-6


def test_holding_the_start_pose_keeps_the_hand_still(start):
    station = make_hsr_station(command="pose")
    builder = DiagramBuilder()
    builder.AddSystem(station)
    hold = builder.AddSystem(ConstantVectorSource(start))
    builder.Connect(hold.get_output_port(), station.GetInputPort("pose_command"))
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(1.0)
    hand = station.GetOutputPort("hand_pose").Eval(
        station.GetMyContextFromRoot(simulator.get_context()))
    np.testing.assert_allclose(hand, start, atol=1e-9)


def test_the_hand_settles_on_each_commanded_orientation(turns):
    result, checks = turns
    for time in checks:
        column = result.at(time)
        commanded = result.commands[:, column]
        hand = result.hand[:, column]
        assert np.linalg.norm(hand[:3] - commanded[:3]) < POSITION_TOLERANCE, time
        assert angle_between(hand[3:7], commanded[3:7]) < ANGLE_TOLERANCE, time
    # Pitched down, the hand points at the floor: a top grasp.
    pitched = result.hand[3:7, result.at(checks[1])]
    np.testing.assert_allclose(approach_direction(pitched), [0, 0, -1], atol=1e-3)


def test_the_hand_turns_along_with_the_command_as_it_moves(turns):
    # Not only at the end: the hand follows the turning command throughout.
    result, _ = turns
    angles = angle_between(result.hand[3:7], result.commands[3:7])
    assert np.degrees(angles.max()) < 3.0
    assert np.linalg.norm(result.hand[:3] - result.commands[:3], axis=0).max() < 0.02


SCENE_GRASPS = {  # (seed, object): a near side grasp and a near top grasp
    "side": (2, 1),
    "top": (0, 1),
}


@pytest.fixture(scope="module", params=list(SCENE_GRASPS))
def grasp_drive(request, start):
    """The hand driven from its start to a grasp pose of a grasp scene (as
    `sample_grasp_scene` draws it) at 0.12 m/s and 0.4 rad/s at most, then held 3 s."""
    seed, index = SCENE_GRASPS[request.param]
    scene = sample_grasp_scene(seed)
    assert scene.approaches[index] == request.param
    goal, orientation = scene.grasp_positions[index], scene.grasp_orientations[index]
    duration = max(np.linalg.norm(goal - start[:3]) / 0.12,
                   angle_between(orientation, start[3:7]) / 0.4)
    return drive([(0.0, duration, goal, orientation)], duration + 3.0), goal, orientation


def test_a_side_and_a_top_grasp_of_a_grasp_scene_are_reached(grasp_drive):
    result, goal, orientation = grasp_drive
    hand = result.hand[:, -1]
    assert np.linalg.norm(hand[:3] - goal) < POSITION_TOLERANCE
    assert angle_between(hand[3:7], orientation) < ANGLE_TOLERANCE
    assert grasp_success(hand[:3], hand[3:7], goal, orientation, SUCCESS_DISTANCE,
                         SUCCESS_ANGLE)


def test_joints_never_leave_their_limits(turns, grasp_drive):
    lower, upper, speed, torso = plant_limits()
    for result in (turns[0], grasp_drive[0]):
        q = result.states[:lower.size]
        v = result.states[lower.size:]
        # The plan keeps within them; the stiff servos track it to a few microradians.
        assert (q >= lower[:, None] - 1e-4).all() and (q <= upper[:, None] + 1e-4).all()
        moving = np.delete(np.abs(v), torso, axis=0)  # the torso follows the lift
        # The plan keeps each joint's speed within its limit; the servos overshoot it by
        # up to 2.2 % (the arm lift, rising at its limit while the wrist flex sits on its
        # lower limit in the top grasp, measured), never more than 3 %.
        assert (moving <= np.delete(speed, torso)[:, None] * 1.03 + 1e-6).all()


@pytest.mark.parametrize("entry, value, message", [
    (11, np.nan, "pose_command wy is NaN or infinite"),
    (0, np.inf, "pose_command x is NaN or infinite"),
    (3, 2.0, "is not a unit quaternion"),
])
def test_a_command_that_is_not_a_pose_is_refused_by_name(start, entry, value, message):
    station = make_hsr_station(command="pose")
    context = station.CreateDefaultContext()
    command = start.copy()
    command[entry] = value
    station.GetInputPort("pose_command").FixValue(context, command)
    simulator = Simulator(station, context)
    with pytest.raises(ValueError, match=message):
        simulator.AdvanceTo(0.05)


def test_the_pose_station_has_pose_ports_and_an_unknown_command_is_refused():
    station = make_hsr_station(HsrStationConfig(), command="pose")
    assert station.HasInputPort("pose_command") and not station.HasInputPort("ee_command")
    assert station.HasOutputPort("hand_pose") and station.HasOutputPort("ee_state")
    assert not make_hsr_station().HasOutputPort("hand_pose")
    with pytest.raises(ValueError, match="command must be one of"):
        make_hsr_station(command="twist")


def test_a_control_loop_ticking_the_next_pose_finds_the_hand_there_at_each_tick(start):
    # As PoseHandOver sends it: at each tick the pose to be at at the next tick and the
    # twist to move at. The station ramps into it between ticks, so at every tick the hand
    # is where the command of the tick before put it, turning and moving at once.
    period = 0.03
    station = make_hsr_station(HsrStationConfig(control_period=period), command="pose")
    p, q = start[:3], start[3:7]
    segments = [(0.5, 2.0, p + [0.1, 0.1, 0.05], turned([0, 0, 1], 45, q)),
                (3.5, 2.5, p, turned([0, 1, 0], 90, q))]
    builder = DiagramBuilder()
    builder.AddSystem(station)
    # The command sampled at tick k is the waypoints' pose at tick k + 1.
    ahead = builder.AddSystem(PoseWaypoints(start, [(s[0] - period, *s[1:])
                                                    for s in segments]))
    hold = builder.AddSystem(ZeroOrderHold(period, PoseState.size))
    builder.Connect(ahead.get_output_port(), hold.get_input_port())
    builder.Connect(hold.get_output_port(), station.GetInputPort("pose_command"))
    now = builder.AddSystem(PoseWaypoints(start, segments))
    hands = LogVectorOutput(station.GetOutputPort("hand_pose"), builder, period)
    poses = LogVectorOutput(now.get_output_port(), builder, period)
    simulator = Simulator(builder.Build())
    hold.SetVectorState(hold.GetMyMutableContextFromRoot(simulator.get_mutable_context()),
                        start)
    simulator.AdvanceTo(7.0)
    hand = hands.FindLog(simulator.get_context()).data()
    pose = poses.FindLog(simulator.get_context()).data()
    assert np.linalg.norm(hand[:3] - pose[:3], axis=0).max() < 0.002
    assert np.degrees(angle_between(hand[3:7], pose[3:7]).max()) < 1.0
    assert np.degrees(angle_between(hand[3:7, -1], pose[3:7, -1])) < 0.01
