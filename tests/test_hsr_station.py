"""Tests of the HSR station as its user sees it: the hand follows end-effector commands
(position and heading), the base takes over what the arm cannot reach, and the hand
stays at the object height while doing so."""

import numpy as np
import pytest
from pydrake.geometry import Meshcat
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from pbp_drake.robots.hsr_model import BASE_JOINT_NAME
from pbp_drake.robots.hsr_station import add_hsr_station

EE_HEIGHT = 0.7
BASE_RADIUS = 0.226  # the lower base's cylinder in the model


def simulate(knots, duration, **station_args):
    """Runs the station under a piecewise-linear command through ``knots``
    (a list of (time, 7-vector)) and returns the station, the ee_state log and the
    base (x, y, yaw) log, both sampled every 10 ms."""
    builder = DiagramBuilder()
    station = add_hsr_station(builder, **station_args)
    times = [t for t, _ in knots]
    values = np.column_stack([c for _, c in knots])
    source = builder.AddSystem(
        TrajectorySource(PiecewisePolynomial.FirstOrderHold(times, values)))
    builder.Connect(source.get_output_port(), station.ee_command)
    ee_logger = LogVectorOutput(station.ee_state, builder, 0.01)
    state_logger = LogVectorOutput(
        station.plant.get_state_output_port(station.model), builder, 0.01)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.AdvanceTo(duration)
    context = simulator.get_context()
    base = station.plant.GetJointByName(BASE_JOINT_NAME, station.model).position_start()
    state_log = state_logger.FindLog(context)
    return station, ee_logger.FindLog(context), state_log.data()[base:base + 3]


def ramp(start, delta, speed):
    """Knots of a straight command ramp from ``start`` by ``delta`` (position part) at
    ``speed`` (m/s), and the ramp's duration."""
    duration = np.linalg.norm(delta[:3]) / speed
    return [(0.0, start), (duration, start + delta)], duration


@pytest.fixture(scope="module")
def start():
    builder = DiagramBuilder()
    return add_hsr_station(builder).initial_ee_state[:7]


def test_starts_level_in_front_of_the_base_at_object_height():
    builder = DiagramBuilder()
    station = add_hsr_station(builder)
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    ee_state = station.ee_state.Eval(station.ee_state.get_system().GetMyContextFromRoot(context))
    np.testing.assert_allclose(ee_state, station.initial_ee_state, atol=1e-9)
    p, v, heading, heading_rate = ee_state[:3], ee_state[3:6], ee_state[6], ee_state[7]
    assert p[2] == pytest.approx(EE_HEIGHT, abs=1e-9)
    assert p[0] > BASE_RADIUS + 0.1  # in front of the base, not above the body
    assert heading == pytest.approx(0.0, abs=1e-9)
    np.testing.assert_allclose(v, 0.0)
    assert heading_rate == 0.0
    # The hand points horizontally forward.
    plant = station.plant
    plant_context = plant.GetMyContextFromRoot(context)
    z_axis = plant.GetFrameByName("hand_ee_link").CalcPoseInWorld(
        plant_context).rotation().matrix()[:, 2]
    np.testing.assert_allclose(z_axis, [1, 0, 0], atol=1e-9)


def test_initial_base_pose_moves_the_start():
    builder = DiagramBuilder()
    station = add_hsr_station(builder, initial_base=(1.0, -0.5, np.pi / 2))
    p, heading = station.initial_ee_state[:3], station.initial_ee_state[6]
    assert heading == pytest.approx(np.pi / 2, abs=1e-9)
    assert p[2] == pytest.approx(EE_HEIGHT, abs=1e-9)
    assert p[1] > -0.5 + BASE_RADIUS  # in front of the base, which faces +y


def test_rejects_an_unreachable_start_height():
    with pytest.raises(ValueError, match="ee_height"):
        add_hsr_station(DiagramBuilder(), ee_height=2.0)


def test_holding_the_initial_command_keeps_the_hand_still(start):
    _, ee_log, base_log = simulate([(0.0, start), (2.0, start)], 2.0)
    drift = np.linalg.norm(ee_log.data()[:3] - start[:3, None], axis=0)
    assert drift.max() < 1e-3
    assert np.abs(base_log - base_log[:, :1]).max() < 1e-3


@pytest.mark.parametrize("axis", [0, 1], ids=["forward", "sideways"])
def test_position_ramp_is_tracked_and_moves_the_base(start, axis):
    delta = np.zeros(7)
    delta[axis] = 0.45  # 0.15 m/s for 3 s: beyond what the arm alone reaches
    knots, duration = ramp(start, delta, speed=0.15)
    assert duration == pytest.approx(3.0)
    _, ee_log, base_log = simulate(knots, duration)
    p = ee_log.data()[:3]
    assert np.linalg.norm(p[:, -1] - (start + delta)[:3]) < 0.03
    assert np.abs(p[2] - EE_HEIGHT).max() < 0.02
    # The hand moves at the commanded speed mid-ramp (ee_state's velocity part).
    middle = np.argmin(np.abs(ee_log.sample_times() - duration / 2))
    assert ee_log.data()[3 + axis, middle] == pytest.approx(0.15, abs=0.02)
    # The base carried a good part of the motion, and did not turn.
    assert base_log[axis, -1] - base_log[axis, 0] > 0.2
    assert np.abs(base_log[2]).max() < 0.05


def test_heading_ramp_turns_the_hand_and_the_base_follows(start):
    turned = start.copy()
    turned[6] = 0.5
    _, ee_log, base_log = simulate([(0.0, start), (1.0, turned)], 3.0)
    heading = ee_log.data()[6]
    assert heading[-1] == pytest.approx(0.5, abs=0.05)
    assert np.abs(ee_log.data()[7]).max() > 0.3  # heading_rate saw the turn
    assert np.linalg.norm(ee_log.data()[:3, -1] - start[:3]) < 0.01
    assert np.abs(ee_log.data()[2] - EE_HEIGHT).max() < 0.02
    # The arm drifts back to its ready pose, so the base ends up facing the new heading.
    assert base_log[2, -1] > 0.35


def test_reaches_a_point_in_the_object_region(start):
    target = np.array([2.0, 0.8, EE_HEIGHT])
    delta = np.zeros(7)
    delta[:3] = target - start[:3]
    knots, duration = ramp(start, delta, speed=0.2)
    _, ee_log, _ = simulate(knots, duration)
    p = ee_log.data()[:3]
    assert np.linalg.norm(p[:, -1] - target) < 0.05
    assert np.abs(p[2] - EE_HEIGHT).max() < 0.02


def test_coarser_diff_ik_period_still_tracks(start):
    delta = np.zeros(7)
    delta[1] = 0.3
    knots, duration = ramp(start, delta, speed=0.15)
    _, ee_log, _ = simulate(knots, duration, diff_ik_time_step=0.02)
    p = ee_log.data()[:3]
    assert np.linalg.norm(p[:, -1] - (start + delta)[:3]) < 0.03
    assert np.abs(p[2] - EE_HEIGHT).max() < 0.02


def test_meshcat_visualizer_draws_the_robot():
    meshcat = Meshcat()
    builder = DiagramBuilder()
    station = add_hsr_station(builder, meshcat=meshcat)
    builder.ExportInput(station.ee_command, "ee_command")
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    diagram.get_input_port().FixValue(context, station.initial_ee_state[:7])
    diagram.ForcedPublish(context)
    assert station.visualizer is not None
    assert meshcat.HasPath("/drake/visualizer/hsrb")


def test_base_pd_pushes_only_the_base_toward_the_desired_state():
    from pydrake.multibody.plant import MultibodyPlant

    from pbp_drake.robots.hsr_model import add_hsr
    from pbp_drake.robots.hsr_station import BASE_KD, BASE_KP, base_pd_gain

    plant = MultibodyPlant(0.005)
    model = add_hsr(plant)
    plant.Finalize()
    base = plant.GetJointByName(BASE_JOINT_NAME, model)
    nq, nv = plant.num_positions(), plant.num_velocities()
    rng = np.random.default_rng(0)
    desired, state = rng.normal(size=nq + nv), rng.normal(size=nq + nv)
    force = base_pd_gain(plant, base, BASE_KP, BASE_KD) @ np.concatenate([desired, state])
    q = slice(base.position_start(), base.position_start() + 3)
    v = slice(nq + base.velocity_start(), nq + base.velocity_start() + 3)
    on_base = slice(base.velocity_start(), base.velocity_start() + 3)
    np.testing.assert_allclose(
        force[on_base], np.multiply(BASE_KP, desired[q] - state[q])
        + np.multiply(BASE_KD, desired[v] - state[v]), rtol=1e-12)
    assert not np.delete(force, np.arange(nv)[on_base]).any()
