"""Tests of the arm station as a user with their own URDF sees it: the shipped 7-joint arm
and a 6-joint arm of other kinematics (`models/pbp_arm6_other.urdf`, a test asset) follow
end-effector commands within their joints' limits, start still, and a model, frame or
configuration that cannot work is refused in one line naming its field."""

import dataclasses
import pathlib

import numpy as np
import pytest
from pydrake.lcm import DrakeLcm
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput

from pbp_drake.robots import (
    ArmStationConfig, CylinderObstacle, HsrStationConfig, arm_driver_sim, arm_initial_ee_state,
    arm_reach, arm_ready_ee_state, arm_station_plant, make_arm_station,
    measured_ready_positions)
from pbp_drake.robots.hsr_model import models_dir
from pbp_drake.scenarios import load_scenario_file

from station_drive import CONTROL_PERIOD, drive

REPO = pathlib.Path(__file__).resolve().parents[2]
ARM6 = pathlib.Path(__file__).resolve().parent / "models" / "pbp_arm6_other.urdf"
ARM7_FILE = models_dir() / "pbp_drake_models" / "arm7" / "pbp_arm7.urdf"


def shipped_arm():
    """The arm of diagrams/arm_reach.yaml, as its station config."""
    return load_scenario_file(REPO / "diagrams" / "arm_reach.yaml").scenario.robot.station_config()


def other_arm():
    """The 6-joint test arm, with the ready configuration written in its file."""
    text = ARM6.read_text()
    ready = text.split("ready configuration: [")[1].split("]")[0]
    return ArmStationConfig(model_file=str(ARM6), base_frame="arm6_base", ee_frame="arm6_tool",
                            initial_positions=[float(v) for v in ready.split(",")])


ARMS = {"arm7": shipped_arm, "arm6": other_arm}


@pytest.fixture(params=sorted(ARMS))
def arm(request):
    return dataclasses.replace(ARMS[request.param](), control_period=CONTROL_PERIOD)


@pytest.mark.slow
@pytest.mark.parametrize("motion", ["kinematic", "dynamic"])
def test_holding_the_start_keeps_the_arm_still(arm, motion):
    station = make_arm_station(dataclasses.replace(arm, motion=motion))
    start = arm_initial_ee_state(station)
    np.testing.assert_allclose(start, arm_ready_ee_state(arm), atol=1e-9)
    builder = DiagramBuilder()
    builder.AddSystem(station)
    hold = builder.AddSystem(ConstantVectorSource(start[:7]))
    builder.Connect(hold.get_output_port(), station.GetInputPort("ee_command"))
    log = LogVectorOutput(station.GetOutputPort("ee_state"), builder, 0.05)
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(1.0)
    hands = log.FindLog(simulator.get_context()).data()
    assert np.abs(hands[:3] - start[:3, None]).max() < 1e-5


@pytest.mark.slow
@pytest.mark.parametrize("direction", [(1, 0, 0), (0, 1, 0), (0, 0, 1), (0.6, -0.6, -0.5)])
def test_the_hand_moves_at_the_commanded_velocity_within_the_joint_limits(arm, direction):
    unit = np.asarray(direction, float) / np.linalg.norm(direction)
    station = make_arm_station(arm)
    result = drive(lambda time: 0.12 * unit, 1.5, station=station, state_period=0.01)
    speeds = result.speeds(unit)[10:]  # settled after a third of a second
    assert np.abs(speeds - 0.12).max() < 0.002
    sideways = np.diff(result.hands, axis=1) / CONTROL_PERIOD
    sideways -= np.outer(unit, unit @ sideways)
    assert np.abs(sideways[:, 10:]).max() < 0.002
    plant = arm_station_plant(station)
    q = result.states[:plant.num_positions()]
    v = result.states[plant.num_positions():]
    assert (q >= plant.GetPositionLowerLimits()[:, None] - 1e-9).all()
    assert (q <= plant.GetPositionUpperLimits()[:, None] + 1e-9).all()
    assert (np.abs(v) <= plant.GetVelocityUpperLimits()[:, None] + 1e-9).all()


@pytest.mark.slow
def test_the_heading_turns_the_tool_about_the_vertical(arm):
    result = drive(lambda time: np.zeros(3), 1.5, station=make_arm_station(arm),
                   turn=lambda time: 0.5 * min(time, 1.0))
    assert abs(result.headings[-1] - result.headings[0] - 0.5) < 0.01
    # The driver re-integrates from the measured hand, so what the turn drags it off by
    # stays: a few millimetres.
    assert np.abs(result.hands[:, -1] - result.hands[:, 0]).max() < 0.005


def test_obstacles_are_measured_against_the_arm():
    config = dataclasses.replace(shipped_arm(), obstacles=[CylinderObstacle(0.05, 1.0)])
    station = make_arm_station(config)
    context = station.CreateDefaultContext()
    hand = arm_initial_ee_state(station)
    station.GetInputPort("ee_command").FixValue(context, hand[:7])
    port = station.GetInputPort("obstacle_positions")
    port.FixValue(context, [hand[0], hand[1], 0.5])  # through the hand
    assert station.GetOutputPort("in_collision").Eval(context)[0] == 1.0
    port.FixValue(context, [-1.0, 1.0, 0.5])  # well away
    assert station.GetOutputPort("clearance").Eval(context)[0] > 0.5


REFUSALS = [
    ("missing file", lambda tmp: {"model_file": str(tmp / "nowhere.urdf")},
     "ArmStationConfig.model_file: no file at"),
    ("not a model", lambda tmp: {"model_file": _write(tmp / "bad.urdf", "<robot><link")},
     "does not load"),
    ("unknown frame", lambda tmp: {"ee_frame": "gripper"},
     "ArmStationConfig.ee_frame 'gripper' is not a frame of"),
    ("base not the root", lambda tmp: {"base_frame": "arm7_link3"},
     "ArmStationConfig.base_frame 'arm7_link3' is not the model's root"),
    ("end effector fixed to the base", lambda tmp: {"ee_frame": "arm7_base"},
     "ArmStationConfig.ee_frame 'arm7_base' is not on the arm"),
    ("wrong count", lambda tmp: {"initial_positions": [0.0, 0.0]},
     "ArmStationConfig.initial_positions has 2 entries; the arm has 7 joints"),
    ("outside the limits", lambda tmp: {"initial_positions": [9.0] * 7},
     "ArmStationConfig.initial_positions: joint 'arm7_joint1' at 9 is outside its limits"),
    ("base pose without yaw", lambda tmp: {"base_pose": [0.0, 0.0, 0.0]},
     "ArmStationConfig.base_pose must be finite [x, y, z, yaw], got [0.0, 0.0, 0.0]"),
    ("a NaN position", lambda tmp: {"initial_positions": [np.nan] * 7},
     "ArmStationConfig.initial_positions must be finite, got [nan, "),
    ("positions None", lambda tmp: {"initial_positions": None},
     "ArmStationConfig.initial_positions must be a list, each a number, got None"),
    ("a tool pose as a dict", lambda tmp: {"ready_tool_pose": {"position": [0.5, 0.0, 0.5]}},
     "ArmStationConfig.ready_tool_pose must be a ToolPose or None, got {'position': "),
    ("a radius as text", lambda tmp: {"obstacles": [CylinderObstacle(radius="0.1")]},
     "ArmStationConfig.obstacles[0].radius must be a number, got '0.1'"),
    ("hardware as a dict", lambda tmp: {"hardware": {"driver": "panda"}},
     "ArmStationConfig.hardware must be an ArmHardware or None, got {'driver': 'panda'}"),
    ("negative singular margin", lambda tmp: {"singular_margin": -1.0},
     "ArmStationConfig.singular_margin must be >= 0, got -1.0"),
    ("negative limit margin", lambda tmp: {"limit_margin": -0.1},
     "ArmStationConfig.limit_margin must be >= 0, got -0.1"),
    ("no room between the limits", lambda tmp: {"model_file": _arm7_with(
        tmp, ('<limit lower="0" upper="3.05"', '<limit lower="0.5" upper="0.5"'))},
     "joint 'arm7_joint4' has position limits [0.5, 0.5] with no room between them"),
    # Without its transmission: Drake's parser refuses a motor on a planar joint itself.
    ("a planar joint", lambda tmp: {"model_file": _arm7_with(
        tmp, ('<joint name="arm7_joint4" type="revolute"', '<joint name="arm7_joint4" '
              'type="planar"'), (TRANSMISSION4, ""))},
     "joint 'arm7_joint4' is a planar joint; the station moves revolute and prismatic joints "
     "only"),
]
TRANSMISSION4 = ARM7_FILE.read_text().split('  <transmission name="arm7_transmission4">')[1]
TRANSMISSION4 = ('  <transmission name="arm7_transmission4">'
                 + TRANSMISSION4[:TRANSMISSION4.index("</transmission>")] + "</transmission>")


def _write(path, text):
    path.write_text(text)
    return str(path)


def _arm7_with(tmp, *changes):
    """The shipped arm's file with each `(old, new)` of `changes` made once."""
    text = ARM7_FILE.read_text()
    for old, new in changes:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    return _write(tmp / "arm.urdf", text)


@pytest.mark.parametrize("name, change, message", REFUSALS, ids=[r[0] for r in REFUSALS])
def test_a_model_that_cannot_work_is_refused_in_one_line(tmp_path, name, change, message):
    config = dataclasses.replace(shipped_arm(), **change(tmp_path))
    with pytest.raises(ValueError) as error:
        make_arm_station(config)
    text = str(error.value)
    assert message in text and "\n" not in text, text


@pytest.mark.parametrize("config", [None, {"model_file": str(ARM6)}, HsrStationConfig()])
def test_a_config_of_another_type_is_refused_by_name(config):
    for call in (make_arm_station, arm_ready_ee_state, arm_reach, measured_ready_positions):
        with pytest.raises(ValueError, match=f"^config must be ArmStationConfig, got "
                                             f"{type(config).__name__}$"):
            call(config)
    with pytest.raises(ValueError, match="^config must be ArmStationConfig, got "):
        arm_driver_sim(config, DrakeLcm("memq://"))


def test_the_start_is_read_from_a_station_not_its_config():
    for call in (arm_initial_ee_state, arm_station_plant):
        with pytest.raises(ValueError, match=r"^station must be the Diagram of make_hsr_station "
                                             r"or make_arm_station, got ArmStationConfig"):
            call(shipped_arm())


def test_numpy_arrays_are_lists_of_numbers():
    listed = shipped_arm()
    arrays = dataclasses.replace(listed, initial_positions=np.array(listed.initial_positions),
                                 base_pose=np.array(listed.base_pose))
    np.testing.assert_array_equal(arm_ready_ee_state(arrays), arm_ready_ee_state(listed))


def test_a_joint_without_limits_is_refused_naming_it(tmp_path):
    text = ARM7_FILE.read_text()
    start = text.index('<joint name="arm7_joint4"')
    end = text.index("</joint>", start)
    joint = text[start:end]
    limit = joint[joint.index("<limit"):joint.index("/>", joint.index("<limit")) + 2]
    unlimited = tmp_path / "arm.urdf"
    unlimited.write_text(text[:start] + joint.replace(limit, "") + text[end:])
    config = dataclasses.replace(shipped_arm(), model_file=str(unlimited))
    with pytest.raises(ValueError, match="joint 'arm7_joint4' has no position limits"):
        make_arm_station(config)


def test_a_joint_without_a_motor_in_the_model_is_given_one(tmp_path):
    config = dataclasses.replace(shipped_arm(), motion="dynamic", model_file=_arm7_with(
        tmp_path, (TRANSMISSION4, "")))
    plant = arm_station_plant(make_arm_station(config))
    assert plant.HasJointActuatorNamed("arm7_joint4_pbp_motor")
    assert plant.num_actuators() == 7


def test_the_reach_is_measured_from_the_shoulder():
    shoulder, reach = arm_reach(shipped_arm())
    np.testing.assert_allclose(shoulder, [0.0, 0.0, 0.16])  # the first joint, above the base
    assert reach == pytest.approx(1.14)
