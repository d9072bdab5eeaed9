"""Tests of the HSR station as its user sees it: one Diagram whose hand follows
end-effector commands (position and heading), whose base (driven by the plant's own PD,
within its velocity limits) takes over what the arm cannot reach, and which measures the
robot against obstacles placed through a port."""

import dataclasses

import numpy as np
import pytest
from pydrake.common.yaml import yaml_dump_typed, yaml_load_typed
from pydrake.geometry import Meshcat
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from pbp_drake.robots import (
    ArmStationConfig, CylinderObstacle, HsrStationConfig, hsr_initial_ee_state,
    hsr_initial_hand_pose, hsr_ready_ee_state, hsr_station_plant, make_hsr_station)
from pbp_drake.robots.hsr_station import hsr_ready_palm_position
from pbp_drake.robots.hsr_model import (
    BASE_JOINT_NAMES, TORSO_JOINT_NAME, TORSO_TO_ARM_LIFT_RATIO, add_hsr)
from pbp_drake.systems.ports import EeCommand, EeState

EE_HEIGHT = 0.7
BASE_RADIUS = 0.226  # the lower base's cylinder in the model
BASE_SPEED_LIMITS = (0.2, 0.2, 1.0)  # published, in the model file


def position_indices():
    """Where each joint sits in the plant's positions, by name."""
    plant = MultibodyPlant(0.005)
    model = add_hsr(plant)
    plant.Finalize()
    return {plant.get_joint(index).name(): plant.get_joint(index).position_start()
            for index in plant.GetJointIndices(model)}


POSITION_INDEX = position_indices()
BASE = [POSITION_INDEX[name] for name in BASE_JOINT_NAMES]


def simulate(knots, duration, with_desired_state=False, **config_args):
    """Runs the station under a piecewise-linear command through ``knots``
    (a list of (time, 7-vector)) and returns the ee_state log and the plant state log
    (and, ``with_desired_state``, the desired_state log), sampled every 10 ms."""
    station = make_hsr_station(HsrStationConfig(**config_args))
    builder = DiagramBuilder()
    builder.AddNamedSystem("hsr_station", station)
    times = [t for t, _ in knots]
    values = np.column_stack([c for _, c in knots])
    source = builder.AddSystem(
        TrajectorySource(PiecewisePolynomial.FirstOrderHold(times, values)))
    builder.Connect(source.get_output_port(), station.GetInputPort("ee_command"))
    ee_logger = LogVectorOutput(station.GetOutputPort("ee_state"), builder, 0.01)
    state_logger = LogVectorOutput(station.GetOutputPort("state"), builder, 0.01)
    desired_logger = LogVectorOutput(station.GetOutputPort("desired_state"), builder, 0.01)
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(duration)
    context = simulator.get_context()
    logs = ee_logger.FindLog(context), state_logger.FindLog(context)
    return logs + (desired_logger.FindLog(context),) if with_desired_state else logs


def ramp(start, delta, speed):
    """Knots of a straight command ramp from ``start`` by ``delta`` (position part) at
    ``speed`` (m/s), the command carrying its velocity (``EeCommand``: ``[p, v,
    heading]``), and the ramp's duration."""
    duration = np.linalg.norm(delta[:3]) / speed
    moving = np.zeros(EeCommand.size)
    moving[3:6] = delta[:3] / duration
    return [(0.0, start + moving), (duration, start + delta + moving)], duration


@pytest.fixture(scope="module")
def station():
    return make_hsr_station()


@pytest.fixture(scope="module")
def start(station):
    return hsr_initial_ee_state(station)[:EeCommand.size]


def test_is_one_diagram_with_named_ports(station):
    assert station.get_name() == "hsr_station"
    assert [station.get_input_port(i).get_name() for i in range(station.num_input_ports())] \
        == ["ee_command"]
    outputs = {station.get_output_port(i).get_name(): station.get_output_port(i)
               for i in range(station.num_output_ports())}
    assert {"ee_state", "state", "desired_state", "body_poses", "query_object"} \
        == set(outputs)
    assert station.GetInputPort("ee_command").size() == EeCommand.size
    assert outputs["ee_state"].size() == EeState.size
    assert outputs["state"].size() == 2 * 9  # 3 base + torso + 5 arm
    assert outputs["desired_state"].size() == 2 * 8  # every motor: 3 base + 5 arm
    assert "in_collision" not in outputs  # only with obstacles


def test_config_round_trips_through_yaml():
    config = HsrStationConfig(diff_ik_time_step=0.02, control_period=1 / 30,
                              obstacles=[CylinderObstacle(radius=0.1, height=1.0)])
    loaded = yaml_load_typed(schema=HsrStationConfig, data=yaml_dump_typed(config))
    assert loaded.obstacles == config.obstacles
    assert loaded.control_period == config.control_period
    partial = yaml_load_typed(schema=HsrStationConfig, data="plant: {time_step: 0.002}")
    assert partial.plant.time_step == 0.002
    assert partial.plant.discrete_contact_approximation == "sap"  # the defaults are kept
    assert not partial.plant.use_sampled_output_ports
    unlimited = yaml_load_typed(schema=HsrStationConfig,
                                data="arm_acceleration_limits: [.inf, .inf, .inf, .inf, .inf]")
    assert unlimited.arm_acceleration_limits == [np.inf] * 5


@pytest.mark.parametrize("field, value, message", [
    ("diff_ik_time_step", 0.0125, "diff_ik_time_step must be a whole multiple"),
    ("control_period", -0.1, "control_period"),
    ("initial_base", [0.0, 0.0], "initial_base"),
    ("base_kp", [1.0, 1.0], "base_kp"),
    ("base_acceleration_limits", [0.3, 0.3], r"HsrStationConfig\.base_acceleration_limits"),
    ("arm_acceleration_limits", [1.0, 6.0, 40.0, 30.0, 0.0],
     r"HsrStationConfig\.arm_acceleration_limits"),
    ("arm_acceleration_limits", [1.0, 6.0, 40.0, 30.0, float("nan")],
     "arm_acceleration_limits"),
    ("obstacles", [CylinderObstacle(radius=0.0)], r"obstacles\[0\]"),
    ("arm_centering_gain", -1.0, r"HsrStationConfig\.arm_centering_gain must be >= 0, got -1.0"),
    ("ee_height", None, r"HsrStationConfig\.ee_height must be a number, got None"),
    ("control_period", "0.1", r"HsrStationConfig\.control_period must be a number or None, "
                              r"got '0.1'"),
    ("obstacles", [(0.1, 0.5)], r"HsrStationConfig\.obstacles must be a list, each a "
                                r"CylinderObstacle, got \[\(0.1, 0.5\)\]"),
    ("initial_base", [20.0, 0.0, 0.0],
     r"initial_base \[20.0, 0.0, 0.0\] is out of base_x_joint's range"),
])
def test_config_errors_name_the_field(field, value, message):
    with pytest.raises(ValueError, match=message):
        make_hsr_station(dataclasses.replace(HsrStationConfig(), **{field: value}))


@pytest.mark.parametrize("config", [{"control_period": 0.1}, "hsr", ArmStationConfig()])
def test_a_config_of_another_type_is_refused_by_name(config):
    for call in (make_hsr_station, hsr_ready_ee_state):
        with pytest.raises(ValueError, match=f"^config must be HsrStationConfig, got "
                                             f"{type(config).__name__}$"):
            call(config)


@pytest.mark.parametrize("station", [HsrStationConfig(), None])
def test_what_a_station_is_read_from_must_be_a_station(station):
    for call in (hsr_initial_ee_state, hsr_initial_hand_pose, hsr_station_plant):
        with pytest.raises(ValueError, match=(
                rf"^station must be the Diagram of make_hsr_station or make_arm_station, got "
                rf"{type(station).__name__} \(hsr_ready_ee_state and arm_ready_ee_state take "
                r"a config\)$")):
            call(station)


def test_rejects_tamsi_which_ignores_the_torso_coupler():
    config = HsrStationConfig()
    config.plant.discrete_contact_approximation = "tamsi"
    with pytest.raises(ValueError, match="discrete_contact_approximation"):
        make_hsr_station(config)


def test_rejects_a_continuous_plant():
    config = HsrStationConfig()
    config.plant.time_step = 0.0
    with pytest.raises(ValueError, match=r"HsrStationConfig\.plant\.time_step must be positive "
                                         r"\(a discrete plant\), got 0.0"):
        make_hsr_station(config)


def test_rejects_sampled_output_ports():
    # A sample at a tick would see the robot one plant step later at some ticks only.
    config = HsrStationConfig()
    config.plant.use_sampled_output_ports = True
    with pytest.raises(ValueError, match=r"HsrStationConfig\.plant\.use_sampled_output_ports"):
        make_hsr_station(config)


def test_starts_level_in_front_of_the_base_at_object_height(station):
    context = station.CreateDefaultContext()
    ee_state = EeState(station.GetOutputPort("ee_state").Eval(context))
    np.testing.assert_allclose(ee_state[:], hsr_initial_ee_state(station), atol=1e-12)
    assert ee_state.z == pytest.approx(EE_HEIGHT, abs=1e-9)
    assert ee_state.x > BASE_RADIUS + 0.1  # in front of the base, not above the body
    assert ee_state.heading == pytest.approx(0.0, abs=1e-9)
    np.testing.assert_allclose([ee_state.vx, ee_state.vy, ee_state.vz], 0.0)
    assert ee_state.heading_rate == 0.0
    # The hand points horizontally forward.
    plant = station.GetSubsystemByName("plant")
    z_axis = plant.GetFrameByName("hand_ee_link").CalcPoseInWorld(
        plant.GetMyContextFromRoot(context)).rotation().matrix()[:, 2]
    np.testing.assert_allclose(z_axis, [1, 0, 0], atol=1e-9)


def test_initial_base_pose_moves_the_start():
    station = make_hsr_station(HsrStationConfig(initial_base=[1.0, -0.5, np.pi / 2]))
    ee_state = EeState(hsr_initial_ee_state(station))
    assert ee_state.heading == pytest.approx(np.pi / 2, abs=1e-9)
    assert ee_state.z == pytest.approx(EE_HEIGHT, abs=1e-9)
    assert ee_state.y > -0.5 + BASE_RADIUS  # in front of the base, which faces +y


def test_rejects_an_unreachable_start_height():
    with pytest.raises(ValueError, match="ee_height"):
        make_hsr_station(HsrStationConfig(ee_height=2.0))


@pytest.mark.slow
def test_holding_the_initial_command_keeps_still(start):
    ee_log, state_log = simulate([(0.0, start), (2.0, start)], 2.0)
    drift = np.linalg.norm(ee_log.data()[:3] - start[:3, None], axis=0)
    assert drift.max() < 1e-3
    positions = state_log.data()[:9]
    assert np.abs(positions - positions[:, :1]).max() < 1e-3


@pytest.mark.slow
@pytest.mark.parametrize("axis", [0, 1], ids=["forward", "sideways"])
def test_position_ramp_is_tracked_and_moves_the_base(start, axis):
    delta = np.zeros(7)
    delta[axis] = 0.45  # 0.15 m/s for 3 s: beyond what the arm alone reaches
    knots, duration = ramp(start, delta, speed=0.15)
    assert duration == pytest.approx(3.0)
    ee_log, state_log = simulate(knots, duration)
    p = ee_log.data()[:3]
    assert np.linalg.norm(p[:, -1] - (start + delta)[:3]) < 0.03
    assert np.abs(p[2] - EE_HEIGHT).max() < 0.02
    # The hand moves at the commanded speed mid-ramp (ee_state's velocity part), where the
    # command puts it: no lag (a control loop that re-integrates from the robot's state
    # would lose any lag at every tick).
    middle = np.argmin(np.abs(ee_log.sample_times() - duration / 2))
    assert ee_log.data()[3 + axis, middle] == pytest.approx(0.15, abs=1e-3)
    commanded = start[axis] + 0.15 * ee_log.sample_times()[middle]
    assert abs(commanded - p[axis, middle]) < 1e-4
    # The base carried a good part of the motion. Going forward it hardly turned; going
    # sideways, diff IK sets the hand off partly by turning the base (0.15 rad here),
    # which speeds up sideways slowly (its acceleration limit, HsrStationConfig), and the
    # arm's drift back to its ready pose then straightens it.
    base = state_log.data()[BASE]
    assert base[axis, -1] - base[axis, 0] > 0.2
    turn = np.abs(base[2]).max()
    assert turn < (0.05 if axis == 0 else 0.2)
    assert np.abs(base[2, -1]) < 0.5 * turn
    # The torso follows the arm lift (the coupler constraint, enforced by SAP).
    torso = state_log.data()[POSITION_INDEX[TORSO_JOINT_NAME]]
    lift = state_log.data()[POSITION_INDEX["arm_lift_joint"]]
    np.testing.assert_allclose(torso, TORSO_TO_ARM_LIFT_RATIO * lift, atol=1e-4)


@pytest.mark.slow
def test_base_is_driven_within_its_velocity_limits(start):
    # A far, fast command: diff IK asks the base for its full speed (the model file's
    # limits), and the plant's PD on the base motors follows it.
    delta = np.zeros(7)
    delta[:2] = [1.0, 0.6]
    delta[6] = 1.0
    knots, _ = ramp(start, delta, speed=0.5)
    ee_log, state_log, desired_log = simulate(knots, 3.0, with_desired_state=True)
    # desired_state is [q_d, v_d] in motor order, the base's three motors first.
    desired_velocities = desired_log.data()[8:11]
    base_velocities = state_log.data()[9:][BASE]
    for axis, limit in enumerate(BASE_SPEED_LIMITS):
        assert np.abs(desired_velocities[axis]).max() <= limit + 1e-9
        # The PD catches up the lag of setting off with a brief overshoot only.
        assert np.abs(base_velocities[axis]).max() < 1.1 * limit
    assert base_velocities[0, -1] == pytest.approx(BASE_SPEED_LIMITS[0], rel=0.01)


@pytest.mark.slow
def test_heading_ramp_turns_the_hand_and_the_base_follows(start):
    turned = start.copy()
    turned[6] = 0.5
    ee_log, state_log = simulate([(0.0, start), (1.0, turned)], 3.0)
    heading = ee_log.data()[6]
    assert heading[-1] == pytest.approx(0.5, abs=0.05)
    assert np.abs(ee_log.data()[7]).max() > 0.3  # heading_rate saw the turn
    assert np.linalg.norm(ee_log.data()[:3, -1] - start[:3]) < 0.01
    assert np.abs(ee_log.data()[2] - EE_HEIGHT).max() < 0.02
    # The arm drifts back to its ready pose, so the base ends up facing the new heading.
    assert state_log.data()[BASE[2], -1] > 0.35


@pytest.mark.slow
def test_reaches_a_point_in_the_object_region(start):
    target = np.array([2.0, 0.8, EE_HEIGHT])
    delta = np.zeros(7)
    delta[:3] = target - start[:3]
    knots, duration = ramp(start, delta, speed=0.2)
    ee_log, _ = simulate(knots, duration)
    p = ee_log.data()[:3]
    assert np.linalg.norm(p[:, -1] - target) < 0.05
    assert np.abs(p[2] - EE_HEIGHT).max() < 0.02


@pytest.mark.slow
def test_coarser_diff_ik_period_still_tracks(start):
    delta = np.zeros(7)
    delta[1] = 0.3
    knots, duration = ramp(start, delta, speed=0.15)
    ee_log, _ = simulate(knots, duration, diff_ik_time_step=0.02)
    p = ee_log.data()[:3]
    assert np.linalg.norm(p[:, -1] - (start + delta)[:3]) < 0.03
    assert np.abs(p[2] - EE_HEIGHT).max() < 0.02


def obstacle_station_context(centres, meshcat=None):
    """A station with two cylinders at ``centres`` (2, 3), its context, the diagram."""
    station = make_hsr_station(
        HsrStationConfig(obstacles=[CylinderObstacle(0.1, 1.0), CylinderObstacle(0.2, 0.5)]),
        meshcat)
    context = station.CreateDefaultContext()
    station.GetInputPort("obstacle_positions").FixValue(context, np.ravel(centres))
    return station, context


def test_obstacles_are_measured_against_the_robot():
    station, context = obstacle_station_context([[1.0, 0.0, 0.5], [0.0, 2.0, 0.25]])
    assert station.GetInputPort("obstacle_positions").size() == 6
    clearance = station.GetOutputPort("clearance").Eval(context)[0]
    # The first cylinder (radius 0.1) is nearest: 1.0 - 0.1 from the base's axis, less
    # how far the hand (0.53 m ahead of the base) reaches toward it.
    assert 0.2 < clearance < 1.0 - 0.1 - 0.226
    assert station.GetOutputPort("in_collision").Eval(context)[0] == 0.0

    # Moved onto the hand: the same station now reports the overlap.
    hand = hsr_initial_ee_state(station)[:3]
    station.GetInputPort("obstacle_positions").FixValue(
        context, np.concatenate([hand, [0.0, 2.0, 0.25]]))
    assert station.GetOutputPort("clearance").Eval(context)[0] < 0.0
    assert station.GetOutputPort("in_collision").Eval(context)[0] == 1.0


@pytest.mark.slow
def test_obstacles_do_not_push_the_robot(start):
    station, _ = obstacle_station_context([[0.0, 0.0, 0.0]] * 2)
    builder = DiagramBuilder()
    builder.AddNamedSystem("hsr_station", station)
    hand = hsr_initial_ee_state(station)[:3]
    on_robot = builder.AddSystem(ConstantVectorSource(np.concatenate([hand, [0.0, 0.0, 0.3]])))
    builder.Connect(on_robot.get_output_port(), station.GetInputPort("obstacle_positions"))
    hold = builder.AddSystem(ConstantVectorSource(start))
    builder.Connect(hold.get_output_port(), station.GetInputPort("ee_command"))
    log = LogVectorOutput(station.GetOutputPort("in_collision"), builder, 0.1)
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(0.5)
    context = simulator.get_context()
    assert log.FindLog(context).data().min() == 1.0  # inside the obstacles all along
    ee_state = station.GetOutputPort("ee_state").Eval(station.GetMyContextFromRoot(context))
    np.testing.assert_allclose(ee_state[:3], hand, atol=1e-3)


def test_meshcat_draws_the_robot_and_the_obstacles():
    meshcat = Meshcat()
    station, context = obstacle_station_context([[1.0, 0.0, 0.5], [0.0, 2.0, 0.25]], meshcat)
    station.GetInputPort("ee_command").FixValue(context, hsr_initial_ee_state(station)[:7])
    station.ForcedPublish(context)
    assert meshcat.HasPath("/drake/visualizer/hsrb")
    assert meshcat.HasPath("/drake/visualizer/obstacle_0")
    assert meshcat.HasPath("/drake/visualizer/obstacle_1")


def test_meshcat_draws_the_proximity_shapes_when_asked():
    meshcat = Meshcat()
    config = HsrStationConfig()
    config.visualization.publish_proximity = True
    station = make_hsr_station(config, meshcat)
    context = station.CreateDefaultContext()
    station.GetInputPort("ee_command").FixValue(context, hsr_initial_ee_state(station)[:7])
    station.ForcedPublish(context)
    assert meshcat.HasPath("/drake/proximity/hsrb")
    assert meshcat.HasPath("/drake/visualizer/hsrb")


@pytest.mark.parametrize("height, base", [(0.7, [0.0, 0.0, 0.0]), (0.9, [0.4, -0.3, 0.6])])
def test_the_ready_palm_from_the_model_alone_is_where_the_pose_station_starts(height, base):
    # Exactly: the grasping task's DMP duration is resolved from it, and the DMPs start
    # from the station's.
    config = HsrStationConfig(ee_height=height, initial_base=base)
    station = make_hsr_station(config, command="pose")
    np.testing.assert_array_equal(hsr_ready_palm_position(config),
                                  hsr_initial_hand_pose(station)[:3])


@pytest.mark.parametrize("height, base", [(0.7, [0.0, 0.0, 0.0]), (0.9, [0.4, -0.3, 0.6])])
def test_the_ready_state_from_the_model_alone_is_where_the_station_starts(height, base):
    config = HsrStationConfig(ee_height=height, initial_base=base)
    np.testing.assert_allclose(hsr_ready_ee_state(config),
                               hsr_initial_ee_state(make_hsr_station(config)), atol=1e-12)
