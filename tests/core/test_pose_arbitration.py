"""Six-DoF blending laws and hand-over: what the hand is told to do, per mode, with the
orientation on SO(3) and the angular velocity limited per tick."""

import numpy as np
import pytest

from pbp_drake.core import quaternion
from pbp_drake.core.arbitration import validate_mode
from pbp_drake.core.pose_arbitration import (
    POSE_BLEND_LAWS, POSE_BLEND_MODES, HandOverLimits, PoseReference, blend_pose, pose_hand_over,
    turned, validate_twist)

DT = 0.01
ROBOT_POSITION = np.array([0.4, -0.1, 0.8])
ROBOT_ORIENTATION = quaternion.exp_map(np.array([0.2, -0.4, 0.9]))
POLICY = PoseReference(np.array([0.45, -0.05, 0.82]),
                       quaternion.exp_map(np.array([1.0, 0.5, -0.7])),
                       np.array([0.1, 0.2, -0.05]), np.array([0.3, -0.2, 0.6]))
TWIST = np.array([0.05, -0.02, 0.1, -0.4, 0.25, 0.8])


def blend(mode, active=True, alpha=None, twist=TWIST):
    return blend_pose(mode, ROBOT_POSITION, ROBOT_ORIENTATION, POLICY, twist, active, DT,
                      alpha)


def same_orientation(p, q):
    return quaternion.angle_between(p, q) < 1e-12


def test_teleop_passes_the_operator_twist_and_turns_the_hand_by_it():
    reference = blend("teleop", active=True)
    np.testing.assert_array_equal(reference.velocity, TWIST[:3])
    np.testing.assert_array_equal(reference.angular_velocity, TWIST[3:])
    np.testing.assert_allclose(reference.position, ROBOT_POSITION + TWIST[:3] * DT)
    # The hand turned for one period at the world-frame angular velocity w: q' q* = Exp(w dt).
    rotation = quaternion.log_map(quaternion.multiply(
        reference.orientation, quaternion.conjugate(ROBOT_ORIENTATION)))
    np.testing.assert_allclose(rotation, TWIST[3:] * DT, atol=1e-15)


def test_pbp_continuous_adds_the_operator_to_the_policy():
    reference = blend("pbp_continuous")
    np.testing.assert_allclose(reference.velocity, POLICY.velocity + TWIST[:3])
    np.testing.assert_allclose(reference.angular_velocity,
                               POLICY.angular_velocity + TWIST[3:])
    assert same_orientation(reference.orientation, turned(POLICY.orientation, TWIST[3:], DT))


def test_pbp_alternated_gives_the_operator_while_acting_and_the_policy_after():
    acting, idle = blend("pbp_alternated", active=True), blend("pbp_alternated", active=False)
    np.testing.assert_array_equal(acting.angular_velocity, TWIST[3:])
    np.testing.assert_array_equal(idle.angular_velocity, POLICY.angular_velocity)
    assert same_orientation(idle.orientation, POLICY.orientation)


def test_pbp_no_user_ignores_the_operator():
    reference = blend("pbp_no_user", active=True)
    np.testing.assert_array_equal(reference.velocity, POLICY.velocity)
    assert same_orientation(reference.orientation, POLICY.orientation)


@pytest.mark.parametrize("alpha", [0.0, 0.3, 0.75, 1.0])
def test_fixed_alpha_blends_twists_linearly_and_orientations_on_the_geodesic(alpha):
    operator, reference = blend("teleop"), blend("fixed_alpha", alpha=alpha)
    np.testing.assert_allclose(reference.angular_velocity,
                               (1 - alpha) * TWIST[3:] + alpha * POLICY.angular_velocity)
    np.testing.assert_allclose(reference.position,
                               (1 - alpha) * operator.position + alpha * POLICY.position)
    whole = quaternion.angle_between(operator.orientation, POLICY.orientation)
    to_operator = quaternion.angle_between(reference.orientation, operator.orientation)
    to_policy = quaternion.angle_between(reference.orientation, POLICY.orientation)
    # On the shorter arc, alpha of the way from the operator's orientation to the policy's.
    assert to_operator == pytest.approx(alpha * whole, abs=1e-12)
    assert to_operator + to_policy == pytest.approx(whole, abs=1e-12)
    assert abs(np.linalg.norm(reference.orientation) - 1.0) < 1e-15


def test_an_idle_operator_in_fixed_alpha_gives_the_policy():
    reference = blend("fixed_alpha", active=False, alpha=0.2)
    np.testing.assert_array_equal(reference.angular_velocity, POLICY.angular_velocity)


def test_the_policy_on_the_other_hemisphere_is_the_same_orientation():
    flipped = POLICY._replace(orientation=-POLICY.orientation)
    reference = blend_pose("fixed_alpha", ROBOT_POSITION, ROBOT_ORIENTATION, flipped, TWIST,
                           True, DT, 0.5)
    assert same_orientation(reference.orientation, blend("fixed_alpha", alpha=0.5).orientation)


@pytest.mark.parametrize("field, index", [("vy", 1), ("wx", 3), ("wz", 5)])
@pytest.mark.parametrize("mode", POSE_BLEND_MODES)
def test_a_nan_twist_is_refused_with_its_field_named(mode, field, index):
    twist = TWIST.copy()
    twist[index] = np.nan if index != 5 else np.inf
    with pytest.raises(ValueError, match=f"operator_twist {field} is NaN or infinite"):
        blend(mode, alpha=0.5, twist=twist)


@pytest.mark.parametrize("mode", ["teleop", "fixed_alpha"])
def test_an_orientation_that_is_not_a_unit_quaternion_is_refused(mode):
    # Neither is divided by its norm: twice the hand's quaternion would come out of norm 2.
    with pytest.raises(ValueError, match="robot_orientation is not a unit quaternion .* has "
                                         "norm 2;"):
        blend_pose(mode, ROBOT_POSITION, 2.0 * ROBOT_ORIENTATION, POLICY, TWIST, True, DT,
                   0.5)
    tilted = POLICY._replace(orientation=1.01 * POLICY.orientation)
    with pytest.raises(ValueError, match="policy orientation is not a unit quaternion"):
        blend_pose(mode, ROBOT_POSITION, ROBOT_ORIENTATION, tilted, TWIST, True, DT, 0.5)


def test_a_twist_of_the_wrong_size_is_refused():
    with pytest.raises(ValueError, match=r"operator_twist must be 6 numbers .*, got 5"):
        validate_twist(np.zeros(5))


def test_unknown_modes_and_bad_alphas_are_refused():
    with pytest.raises(ValueError, match="unknown"):
        validate_mode("euler_blend", laws=POSE_BLEND_LAWS)
    with pytest.raises(ValueError, match="alpha"):
        validate_mode("fixed_alpha", 1.5, POSE_BLEND_LAWS)


LIMITS = HandOverLimits(2.0, 0.5, 0.3 / DT, 1.5)


@pytest.mark.slow
def test_the_hand_over_bounds_the_change_of_angular_velocity_per_tick():
    rng = np.random.default_rng(2)
    velocity, angular = np.zeros(3), np.zeros(3)
    for _ in range(400):
        reference = PoseReference(rng.normal(size=3), quaternion.exp_map(rng.normal(size=3)),
                                  rng.normal(size=3), 3.0 * rng.normal(size=3))
        command = pose_hand_over(velocity, angular, reference, LIMITS, DT)
        assert np.linalg.norm(command.angular_velocity - angular) <= 0.3 + 1e-12
        assert np.linalg.norm(command.angular_velocity) <= 1.5 + 1e-12
        assert np.linalg.norm(command.velocity - velocity) <= 2.0 * DT + 1e-12
        # The orientation is the reference's, turned by the angular velocity not reached.
        shift = quaternion.log_map(quaternion.multiply(
            command.orientation, quaternion.conjugate(reference.orientation)))
        np.testing.assert_allclose(
            shift, (command.angular_velocity - reference.angular_velocity) * DT, atol=1e-14)
        velocity, angular = command.velocity, command.angular_velocity


def test_the_hand_over_passes_steady_turning_through_unchanged():
    reference = PoseReference(np.ones(3), ROBOT_ORIENTATION, np.full(3, 0.1),
                              np.array([0.2, 0.0, -0.1]))
    command = pose_hand_over([0.1, 0.1, 0.1], [0.21, 0.0, -0.1], reference, LIMITS, DT)
    np.testing.assert_array_equal(command.angular_velocity, reference.angular_velocity)
    assert same_orientation(command.orientation, ROBOT_ORIENTATION)


@pytest.mark.parametrize("index, name", [(0, "max_acceleration"), (2, "max_angular_acceleration"),
                                         (3, "max_angular_speed")])
def test_hand_over_limits_that_are_not_positive_are_refused_by_name(index, name):
    values = list(LIMITS)
    values[index] = -1.0
    with pytest.raises(ValueError, match=name):
        HandOverLimits(*values).checked()
