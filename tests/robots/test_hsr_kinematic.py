"""Tests of the kinematic HSR station (`HsrStationConfig.motion = "kinematic"`): the same
station without the plant's dynamics, its joints on the diff IK's plan, as a user who
switches it on for a faster study sees it."""

import dataclasses
import gc

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.console import RobotCamera
from pbp_drake.robots import (
    CylinderObstacle, HsrStationConfig, hsr_initial_ee_state, hsr_station_plant,
    make_hsr_station)
from pbp_drake.robots.hsr_model import TORSO_TO_ARM_LIFT_RATIO
from pbp_drake.systems.ports import EeCommand

from test_hsr_station import POSITION_INDEX, ramp, simulate

# Its tests share fixtures that take seconds to make: `make test-fast` leaves it out.
pytestmark = pytest.mark.slow

KINEMATIC = HsrStationConfig(motion="kinematic")


def output_names(station):
    return {station.get_output_port(i).get_name() for i in range(station.num_output_ports())}


def test_has_the_dynamic_stations_ports_but_body_poses():
    kinematic, dynamic = make_hsr_station(KINEMATIC), make_hsr_station()
    assert output_names(dynamic) - output_names(kinematic) == {"body_poses"}
    assert output_names(kinematic) <= output_names(dynamic)
    for name in output_names(kinematic) - {"query_object"}:
        assert kinematic.GetOutputPort(name).size() == dynamic.GetOutputPort(name).size()
    assert not kinematic.HasSubsystemNamed("plant")  # nothing is stepped
    np.testing.assert_allclose(hsr_initial_ee_state(kinematic), hsr_initial_ee_state(dynamic),
                               atol=1e-12)


def test_rejects_an_unknown_motion_by_name():
    with pytest.raises(ValueError, match=r"HsrStationConfig\.motion.*'rigid'"):
        make_hsr_station(HsrStationConfig(motion="rigid"))


@pytest.fixture(scope="module")
def both_followed_a_turning_ramp():
    """ee_state logs (every 10 ms) of both stations under one command: forward, sideways,
    up and turning at 0.15 m/s, then slowing to a stop over a second; and the kinematic
    state and desired_state logs."""
    start = hsr_initial_ee_state(make_hsr_station())[:EeCommand.size]
    knots, duration = ramp(start, np.array([0.3, 0.25, 0.05, 0, 0, 0, 0.6]), speed=0.15)
    knots.append((duration + 1.0, knots[-1][1] * np.r_[1, 1, 1, 0, 0, 0, 1]))
    dynamic, _ = simulate(knots, duration + 1.0)
    kinematic, state, desired = simulate(knots, duration + 1.0, with_desired_state=True,
                                         motion="kinematic")
    return dynamic.data(), kinematic.data(), state.data(), desired.data()


def test_the_hand_is_where_the_dynamic_stations_hand_is(both_followed_a_turning_ramp):
    # The dynamic station's servos trail the plan by about a / w^2: a tenth of a mm.
    dynamic, kinematic, _, _ = both_followed_a_turning_ramp
    assert np.abs(kinematic[:3] - dynamic[:3]).max() < 2e-4
    assert np.abs(kinematic[6] - dynamic[6]).max() < 1e-3  # heading, rad
    # Their velocities differ while the plan changes its own every diff IK step (the
    # servos smooth each change over a few ms), and meet again once it holds a velocity.
    assert np.abs(kinematic[3:6] - dynamic[3:6]).max() < 0.02
    np.testing.assert_allclose(kinematic[:6, -1], dynamic[:6, -1], atol=1e-4)


def test_the_joints_are_on_the_plan_with_the_torso_coupled(both_followed_a_turning_ramp):
    _, _, state, desired = both_followed_a_turning_ramp
    motors = 8
    lift, torso = POSITION_INDEX["arm_lift_joint"], POSITION_INDEX["torso_lift_joint"]
    np.testing.assert_allclose(state[torso], TORSO_TO_ARM_LIFT_RATIO * state[lift])
    np.testing.assert_allclose(state[9 + torso], TORSO_TO_ARM_LIFT_RATIO * state[9 + lift])
    plant = hsr_station_plant(make_hsr_station(KINEMATIC))
    motor_joints = [plant.get_joint_actuator(index).joint()
                    for index in plant.GetJointActuatorIndices()]
    q = state[[joint.position_start() for joint in motor_joints]]
    v = state[[9 + joint.velocity_start() for joint in motor_joints]]
    np.testing.assert_array_equal(q, desired[:motors])
    np.testing.assert_array_equal(v, desired[motors:])


def test_measures_obstacles_on_the_robots_geometry():
    config = dataclasses.replace(KINEMATIC, obstacles=[CylinderObstacle(radius=0.1)])
    station = make_hsr_station(config)
    builder = DiagramBuilder()
    builder.AddSystem(station)
    hold = builder.AddSystem(ConstantVectorSource(hsr_initial_ee_state(station)[:7]))
    builder.Connect(hold.get_output_port(), station.GetInputPort("ee_command"))
    builder.ExportInput(station.GetInputPort("obstacle_positions"))
    diagram = builder.Build()
    del builder, station, hold
    gc.collect()  # the plant lives outside the Diagram: it must outlive this scope
    context = diagram.CreateDefaultContext()
    simulator = Simulator(diagram, context)
    station = diagram.GetSubsystemByName("hsr_station")
    station_context = station.GetMyContextFromRoot(context)
    for centre, hit in [((0.0, 0.0, 0.0), True), ((3.0, 3.0, 0.0), False)]:
        diagram.get_input_port(0).FixValue(context, centre)
        simulator.AdvanceTo(context.get_time() + 0.1)
        clearance = station.GetOutputPort("clearance").Eval(station_context)[0]
        assert station.GetOutputPort("in_collision").Eval(station_context)[0] == float(hit)
        assert (clearance < 0) == hit


class CameraRecorder:
    """Records the camera poses set on it, in Meshcat's SetCameraPose's arguments."""

    def __init__(self):
        self.poses = []

    def SetCameraPose(self, camera, target):
        self.poses.append((np.array(camera), np.array(target)))


@pytest.mark.parametrize("motion", ["dynamic", "kinematic"])
def test_the_robot_camera_follows_either_station(motion):
    station = make_hsr_station(HsrStationConfig(motion=motion, initial_base=[1.0, 0.5, 0.0]))
    recorder = CameraRecorder()
    RobotCamera(recorder, station).update(station.CreateDefaultContext())
    (camera, target), = recorder.poses
    assert camera[0] < 1.0 < target[0]  # behind the base at x = 1, looking along +x
    assert camera[1] == pytest.approx(0.5, abs=0.05)
