"""The frame a person steers the hand in from the browser: forward stays where the hand
points on the floor, through pitches down to a top grasp and up, and turns with a yaw or a
top grasp's wrist roll, never jumping."""

import numpy as np
import pytest

from pbp_drake.core.grasp_task import side_grasp_orientation, top_grasp_orientation
from pbp_drake.core.operator_frame import operator_frame, operator_twist
from pbp_drake.core.quaternion import exp_map, multiply

READY = side_grasp_orientation(0.0)


def pitched(degrees, orientation=READY):
    """`orientation` tipped down by `degrees` about world +y (negative: up)."""
    return multiply(exp_map(np.array([0.0, np.radians(degrees), 0.0])), orientation)


@pytest.mark.parametrize("degrees", [-90, -60, -20, 0, 20, 60, 89, 90])
def test_a_pitched_hand_keeps_world_x_as_forward(degrees):
    forward, left, up = operator_frame(pitched(degrees))
    np.testing.assert_allclose(forward, [1, 0, 0], atol=1e-9)
    np.testing.assert_allclose(left, [0, 1, 0], atol=1e-9)
    np.testing.assert_allclose(up, [0, 0, 1])


def test_a_side_grasp_faces_its_yaw_and_a_top_grasp_turns_with_its_roll():
    yaw = 0.7
    forward, _, _ = operator_frame(side_grasp_orientation(yaw))
    np.testing.assert_allclose(forward, [np.cos(yaw), np.sin(yaw), 0], atol=1e-12)
    # The roll is right-handed about z_H, pointing down: clockwise seen from above.
    forward, _, _ = operator_frame(top_grasp_orientation(yaw))
    np.testing.assert_allclose(forward, [np.cos(yaw), -np.sin(yaw), 0], atol=1e-12)


@pytest.mark.slow
def test_the_frame_turns_continuously_while_the_hand_pitches_and_rolls():
    previous = None
    for step in np.linspace(0.0, 1.0, 2001):
        # Pitch from level to straight down while rolling a full turn about z_H.
        roll = exp_map(np.array([0.0, 0.0, 2 * np.pi * step]))
        forward, _, _ = operator_frame(pitched(90 * step, multiply(READY, roll)))
        if previous is not None:
            assert np.linalg.norm(forward - previous) < 0.05, step
        previous = forward


def test_pitch_and_roll_turn_about_left_and_the_approach():
    hand = side_grasp_orientation(np.pi / 2)  # facing world +y, its left world -x
    twist = operator_twist(hand, [0, 0, 0], [0.0, 1.0, 2.0])
    np.testing.assert_allclose(twist, [0, 0, 0, -1.0, 2.0, 0], atol=1e-12)
