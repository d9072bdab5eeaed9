"""MovingObstacles: obstacles wake at their progress threshold and move, at their speed, to
cut the hand off half-way to the target; checked through `obstacle_positions` over time.

The hand slides along +x from the origin to the target at x = 2 at 0.1 m/s, so its progress
is 0.05 per second: obstacle 0 (threshold 0.2075) wakes at the tick of 4.2 s with the hand at
x = 0.42, obstacle 1 (threshold 0.6075) at the tick of 12.2 s with the hand at x = 1.22.
"""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from pbp_drake.core.obstacle_task import ObstacleScene
from pbp_drake.systems.ports import EeState
from pbp_drake.systems.tasks.moving_obstacles import MovingObstacles

PERIOD = 0.1
HAND_SPEED = 0.1
OBSTACLE_SPEED = 0.2
HEIGHT = 0.7
TARGET = np.array([2.0, 0.0, HEIGHT])
# Each wakes with the hand at x_wake and heads for ((x_wake + 2) / 2, 0).
WAKE_TIMES = (4.2, 12.2)
CUT_OFF = np.array([[1.21, 0.0], [1.61, 0.0]])
STARTS = np.array([[1.21, 1.0], [1.61, -0.5]])
SCENE = ObstacleScene(target=TARGET, obstacle_starts=STARTS,
                      thresholds=np.array([0.2075, 0.6075]))


def add_obstacles(builder):
    """MovingObstacles alone: the HSR station holds the cylinders' geometry."""
    return builder.AddSystem(MovingObstacles(
        SCENE, start=[0.0, 0.0, HEIGHT], height=1.0, speed=OBSTACLE_SPEED,
        control_period=PERIOD))


def build():
    builder = DiagramBuilder()
    obstacles = add_obstacles(builder)
    hand = np.zeros((EeState.size, 2))  # at 0 s and at 20 s
    begin, end = EeState(hand[:, 0]), EeState(hand[:, 1])
    begin.z = end.z = HEIGHT
    end.x = HAND_SPEED * 20.0
    begin.vx = end.vx = HAND_SPEED
    ee_state = builder.AddSystem(TrajectorySource(
        PiecewisePolynomial.FirstOrderHold([0.0, 20.0], hand)))
    builder.Connect(ee_state.get_output_port(), obstacles.get_ee_state_input_port())
    return builder.Build(), obstacles


def positions_at(simulator, obstacles, time):
    simulator.AdvanceTo(time)
    context = obstacles.GetMyContextFromRoot(simulator.get_context())
    return obstacles.get_floor_positions_output_port().Eval(context).reshape(-1, 2)


def expected(index, time):
    """Where obstacle `index` stands after the ticks up to `time`."""
    ticks = int(np.floor((time - WAKE_TIMES[index]) / PERIOD + 1e-9)) + 1
    if ticks <= 0:
        return STARTS[index]
    offset = CUT_OFF[index] - STARTS[index]
    distance = np.linalg.norm(offset)
    travel = min(distance, ticks * OBSTACLE_SPEED * PERIOD)
    return STARTS[index] + offset * travel / distance


def test_they_stand_still_until_the_hand_passes_their_threshold():
    diagram, obstacles = build()
    simulator = Simulator(diagram)
    np.testing.assert_array_equal(positions_at(simulator, obstacles, 4.15), STARTS)
    moved = positions_at(simulator, obstacles, 4.25)
    # Obstacle 0 woke at 4.2 s and took one step; obstacle 1 still waits.
    assert np.linalg.norm(moved[0] - STARTS[0]) == pytest.approx(OBSTACLE_SPEED * PERIOD)
    np.testing.assert_array_equal(moved[1], STARTS[1])


@pytest.mark.parametrize("time", [4.25, 6.25, 9.05, 12.15, 12.25, 13.55, 19.0])
def test_they_move_to_the_cut_off_point_at_their_speed_and_stop_there(time):
    diagram, obstacles = build()
    simulator = Simulator(diagram)
    positions = positions_at(simulator, obstacles, time)
    for index in range(2):
        np.testing.assert_allclose(positions[index], expected(index, time), atol=1e-6)


def test_the_centres_stand_on_the_floor_positions_at_half_the_height():
    diagram, obstacles = build()
    simulator = Simulator(diagram)
    floor = positions_at(simulator, obstacles, 13.0)
    context = obstacles.GetMyContextFromRoot(simulator.get_context())
    centres = obstacles.get_obstacle_positions_output_port().Eval(context).reshape(-1, 3)
    np.testing.assert_array_equal(centres[:, :2], floor)
    np.testing.assert_array_equal(centres[:, 2], 0.5)


def test_at_the_end_each_stands_half_way_between_the_hand_at_its_wake_and_the_target():
    diagram, obstacles = build()
    simulator = Simulator(diagram)
    np.testing.assert_allclose(positions_at(simulator, obstacles, 19.0), CUT_OFF, atol=1e-6)
