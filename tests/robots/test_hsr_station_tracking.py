"""The HSR station's hand follows a control loop's command, within the joints' limits.

Driven as the PBP loop drives it (``station_drive``): every 0.03 s the hand's position y is
sampled at the tick and the command is ``[y + v dt, v, heading0]``, re-integrated from the
measured hand, so any lag of the robot behind its command slows the hand. Each drive sets
off from rest at a constant ``v``. Each drive runs on the station's defaults and on the
station of the reaching scenes (``diagrams/hsr_reach.yaml``: kinematic joints, one diff IK
step a control tick).
"""

import functools
import pathlib

import numpy as np
import pytest
from pydrake.multibody.plant import MultibodyPlant

from pbp_drake import load_scenario_file
from pbp_drake.robots import HsrStationConfig
from pbp_drake.robots.hsr_model import ACTUATED_JOINT_NAMES, add_hsr
from station_drive import CONTROL_PERIOD, drive

# Drives of the station (4 s of the fast suite): `make test` runs them.
pytestmark = pytest.mark.slow

DURATION = 5.0
# By then the base has had time to take over from the arm (at its acceleration limit it
# reaches 0.16 m/s in about half a second; the arm then drifts back to its ready pose).
SETTLE = 2.5
DIAGONAL = np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0)
# (direction, speed m/s): along x, along y and diagonal in the floor plane, and a slow
# rise within the arm lift's range (0.25 m of its 0.6 m above the ready pose).
CASES = {
    "x-0.12": ([1.0, 0.0, 0.0], 0.12),
    "x-0.16": ([1.0, 0.0, 0.0], 0.16),
    "back-0.16": ([-1.0, 0.0, 0.0], 0.16),
    "y-0.12": ([0.0, 1.0, 0.0], 0.12),
    "y-0.16": ([0.0, 1.0, 0.0], 0.16),
    "diagonal-0.12": (DIAGONAL, 0.12),
    "diagonal-0.16": (DIAGONAL, 0.16),
    "up-0.05": ([0.0, 0.0, 1.0], 0.05),
}


def motor_limits(config):
    """The velocity limits (the model file's, published) and the acceleration limits (the
    config's) of the motor joints, in ACTUATED_JOINT_NAMES order, and where each joint's
    velocity sits in the plant's state."""
    plant = MultibodyPlant(config.plant.time_step)
    model = add_hsr(plant)
    plant.Finalize()
    joints = [plant.GetJointByName(name, model) for name in ACTUATED_JOINT_NAMES]
    velocities = np.array([joint.velocity_upper_limits()[0] for joint in joints])
    accelerations = np.array(config.base_acceleration_limits + config.arm_acceleration_limits)
    rows = np.array([plant.num_positions() + joint.velocity_start() for joint in joints])
    return velocities, accelerations, rows


@functools.cache
def reach_scenes_station():
    """The station config of the reaching scenes, as their file states it (read once)."""
    repo = pathlib.Path(__file__).resolve().parents[2]
    return load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").resolved.station


STATIONS = {"default": HsrStationConfig, "reach-scenes": reach_scenes_station}
# The most the hand's speed over a tick may exceed the command's, setting off from rest:
# the plan's velocity is constant over a diff IK step, so with one step a tick nothing
# averages the arm's catch-up behind the base's acceleration limit out of a tick (measured
# over these cases: 5.7 % on the default station, 12.2 % on the reaching scenes', both
# diagonally at 0.12 m/s).
OVERSHOOT = {0.01: 1.06, 0.03: 1.125}  # docs/tasks/hsr-station.md: 6 % and 12 %


@pytest.fixture(scope="module", params=[(station, case) for station in STATIONS
                                        for case in CASES],
                ids=lambda param: "-".join(param))
def case(request):
    station, name = request.param
    direction, speed = CASES[name]
    direction = np.asarray(direction, float)
    config = STATIONS[station]()
    return direction, speed, drive(lambda t: speed * direction, DURATION, config), config


def test_hand_moves_at_the_commanded_speed_once_settled(case):
    direction, speed, result, config = case
    speeds = result.speeds(direction) / speed
    settled = speeds[result.tick_times[1:] > SETTLE]
    # Every tick within 0.01 % of the command (docs/tasks/hsr-station.md): no lag, no
    # jitter (measured: at most 0.0045 %).
    assert np.abs(settled - 1.0).max() < 1e-4


def test_hand_never_overshoots_the_commanded_speed(case):
    direction, speed, result, config = case
    speeds = result.speeds(direction) / speed
    assert speeds.max() < OVERSHOOT[config.diff_ik_time_step]
    # Setting off from rest it reaches the command within a few ticks.
    assert np.argmax(speeds > 0.9) * CONTROL_PERIOD < 0.15


def test_hand_keeps_to_the_commanded_direction(case):
    direction, speed, result, config = case
    steps = np.diff(result.hands, axis=1)
    across = steps - np.outer(direction, direction @ steps)
    assert np.linalg.norm(across, axis=0).max() / CONTROL_PERIOD < 0.1 * speed


def test_each_command_starts_from_the_hand_at_its_tick(case):
    # The sample at a tick is the robot at that tick, never one plant step later (the
    # plant's live output ports): the command decided at tick k, logged at tick k + 1,
    # is the hand at tick k plus v dt.
    direction, speed, result, config = case
    commanded_start = result.commands[:3, 1:] - speed * CONTROL_PERIOD * direction[:, None]
    np.testing.assert_allclose(commanded_start, result.hands[:, :-1], atol=1e-12)


def test_joints_keep_within_their_velocity_and_acceleration_limits(case):
    direction, speed, result, config = case
    velocity_limits, acceleration_limits, rows = motor_limits(config)
    # The plan (desired_state's velocities, in motor order) keeps the limits exactly: its
    # velocity changes once a diff IK step, by at most the limit times the step.
    planned = result.desired_states[len(ACTUATED_JOINT_NAMES):]
    assert np.all(np.abs(planned) <= velocity_limits[:, None] + 1e-9)
    changes = np.abs(np.diff(planned, axis=1)).max(axis=1)
    assert np.all(changes <= acceleration_limits * config.diff_ik_time_step + 1e-9)
    # The plant follows it with stiff servos. Its velocities, at every plant step, stay
    # within 2 % of the limits (the servos' catch-up of the plan's position).
    velocities = result.states[rows]
    assert np.all(np.abs(velocities).max(axis=1) <= 1.02 * velocity_limits)
    # Its accelerations, over each control tick: a tick-long window of plant steps can
    # hold the velocity changes of one more diff IK step than its length (the servo
    # realizes each within a plant step or two), so up to (0.03 + 0.01) / 0.03 of the
    # limit.
    stride = round(CONTROL_PERIOD / config.plant.time_step)
    tick_accelerations = np.abs(np.diff(velocities[:, ::stride], axis=1)) / CONTROL_PERIOD
    bound = (CONTROL_PERIOD + config.diff_ik_time_step) / CONTROL_PERIOD
    assert np.all(tick_accelerations.max(axis=1) <= bound * acceleration_limits + 1e-9)


def test_hand_keeps_its_speed_while_its_heading_turns():
    # Along an arc: the hand moves at 0.12 m/s where it points, and its heading turns at
    # 0.8 rad/s (the virtual participant's turning speed), so the base must both turn and
    # swing round.
    rate, speed = 0.8, 0.12

    def velocity(t):
        return speed * np.array([np.cos(rate * t), np.sin(rate * t), 0.0])

    result = drive(velocity, 4.0, turn=lambda t: rate * t)
    steps = np.diff(result.hands, axis=1) / CONTROL_PERIOD
    speeds = np.linalg.norm(steps, axis=0) / speed
    assert speeds.max() < 1.1
    settled = speeds[result.tick_times[1:] > 1.0]
    assert settled.min() > 0.9
    # Each command asks for the next tick's heading; the hand keeps to that ramp, a tick
    # behind the command.
    lag = np.angle(np.exp(1j * (rate * (result.tick_times - CONTROL_PERIOD)
                                - result.headings)))
    assert np.abs(lag[result.tick_times > 1.0]).max() < 0.01


@pytest.mark.parametrize("direction", [[1.0, 0.0, 0.0], DIAGONAL], ids=["x", "diagonal"])
def test_hand_stops_where_it_is_told_to(direction):
    # At 0.16 m/s for 3 s (the base at full speed by then), then v = 0: the hand stops
    # within two ticks and stays, though the base takes half a second to stop.
    direction = np.asarray(direction)
    result = drive(lambda t: 0.16 * direction * (t < 3.0 - 1e-6), 5.0)
    stop = round(3.0 / CONTROL_PERIOD)
    drift = np.linalg.norm(result.hands[:, stop:] - result.hands[:, stop:stop + 1], axis=0)
    assert drift.max() < 0.01
    assert np.abs(result.speeds(direction)[stop + 2:]).max() < 0.02


@pytest.mark.slow
def test_the_published_base_acceleration_would_leave_the_hand_behind():
    # Why HsrStationConfig departs from the published 0.05 m/s² (hsrb_moveit_config): at
    # it the base needs 3.2 s to reach 0.16 m/s, more than the arm can cover, and as long
    # to stop again.
    config = HsrStationConfig(base_acceleration_limits=[0.05, 0.05, 5.0])
    direction = np.array([1.0, 0.0, 0.0])
    result = drive(lambda t: 0.16 * direction * (t < 3.0 - 1e-6), 6.0, config)
    stop = round(3.0 / CONTROL_PERIOD)
    assert (result.speeds(direction)[5:stop] / 0.16).min() < 0.7
    assert np.linalg.norm(result.hands[:, -1] - result.hands[:, stop]) > 0.05
