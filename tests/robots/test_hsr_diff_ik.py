"""The station's own diff IK pieces, alone: the box-constrained QP and the command's ramp."""

import numpy as np
import pytest
from pydrake.math import RigidTransform, RotationMatrix

from pbp_drake.robots.box_qp import solve_box_qp, solve_box_qp_primal
from pbp_drake.robots.hsr_ee_systems import EeCommandToPose


@pytest.mark.parametrize("seed", range(40))
def test_box_qp_meets_the_optimality_conditions(seed):
    rng = np.random.default_rng(seed)
    n = 9
    if seed % 2:
        A = rng.normal(size=(n, n))
        H = A @ A.T + 0.1 * np.eye(n)
    else:  # as ill-conditioned as the diff IK's: a heavy rank-6 task and a light rest
        J = rng.normal(size=(6, n))
        H = 1e6 * J.T @ J + np.eye(n)
    g = rng.normal(size=n) * 5 * np.abs(H).max() ** 0.5
    lower = -rng.uniform(0.0, 1.0, n)
    upper = rng.uniform(0.0, 1.0, n)
    lower[0] = upper[0] = 0.3  # a variable held fixed
    x, hold = solve_box_qp(H, g, lower, upper)
    assert np.all(x >= lower) and np.all(x <= upper)
    gradient = H @ x - g
    tolerance = 1e-9 * np.abs(g).max()
    free = (x > lower) & (x < upper)
    assert np.all(np.abs(gradient[free]) < tolerance)
    assert np.all(gradient[(x <= lower) & (lower < upper)] > -tolerance)
    assert np.all(gradient[(x >= upper) & (lower < upper)] < tolerance)
    # Any first guess of the bounds held gives the same minimum; the primal method, which
    # the primal-dual one falls back to, gives the same numbers bit for bit.
    for guess in (None, hold, -hold, rng.choice([-1.0, 0.0, 1.0], n)):
        if guess is not None:
            np.testing.assert_allclose(solve_box_qp(H, g, lower, upper, guess)[0], x,
                                       atol=1e-9)
        x_guessed, hold_guessed = solve_box_qp(H, g, lower, upper, guess)
        x_primal, hold_primal = solve_box_qp_primal(H, g, lower, upper, guess)
        np.testing.assert_array_equal(x_guessed, x_primal)
        np.testing.assert_array_equal(hold_guessed, hold_primal)


def test_box_qp_without_active_bounds_is_the_unconstrained_minimum():
    H = np.diag([1.0, 2.0])
    x, hold = solve_box_qp(H, np.array([0.5, 1.0]), np.full(2, -10.0), np.full(2, 10.0))
    np.testing.assert_allclose(x, [0.5, 0.5])
    np.testing.assert_array_equal(hold, [0.0, 0.0])


def command_to_pose(command, time, control_period, lead, last_heading=None):
    """The pose and velocity EeCommandToPose outputs at ``time`` for ``command``, the
    last tick's command having had ``last_heading`` (the command's when None)."""
    system = EeCommandToPose(RotationMatrix(), control_period, lead)
    context = system.CreateDefaultContext()
    context.SetTime(time)
    system.get_ee_command_input_port().FixValue(context, command)
    context.SetDiscreteState([command[6] if last_heading is None else last_heading])
    return (system.get_pose_output_port().Eval(context),
            system.get_velocity_output_port().Eval(context))


def test_command_to_pose_reads_the_ramp_lead_ahead():
    # [p, v, heading]: to be at p = 1 at the next tick, moving at 0.3 m/s along x.
    command = np.array([1.0, 0.0, 0.7, 0.3, 0.0, 0.0, 0.0])
    # Inside a tick (0.03 s), the ramp into p read 0.01 s ahead of 0.01 s.
    pose, velocity = command_to_pose(command, 0.01, 0.03, lead=0.01)
    np.testing.assert_allclose(pose.translation(), [1.0 - 0.3 * 0.01, 0.0, 0.7])
    np.testing.assert_allclose(velocity, [0.0, 0.0, 0.0, 0.3, 0.0, 0.0])
    # At the tick itself the command is still the last tick's: it carries on at v.
    pose, _ = command_to_pose(command, 0.03, 0.03, lead=0.01)
    np.testing.assert_allclose(pose.translation(), [1.0 + 0.3 * 0.01, 0.0, 0.7])
    # Without a control period, p carried on at v for lead.
    pose, _ = command_to_pose(command, 0.01, None, lead=0.01)
    np.testing.assert_allclose(pose.translation(), [1.003, 0.0, 0.7])
    assert isinstance(pose, RigidTransform)


def test_command_to_pose_turns_the_heading_at_a_constant_rate():
    # The last tick's command pointed along +x, this one 0.03 rad to the left of it: the
    # heading ramps at 1 rad/s into it by the next tick.
    command = np.array([1.0, 0.0, 0.7, 0.0, 0.0, 0.0, 0.03])
    pose, velocity = command_to_pose(command, 0.01, 0.03, lead=0.01, last_heading=0.0)
    expected = RotationMatrix.MakeZRotation(0.02)
    np.testing.assert_allclose(pose.rotation().matrix(), expected.matrix(), atol=1e-12)
    np.testing.assert_allclose(velocity, [0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    # Across +-pi it turns the short way.
    command[6] = -np.pi + 0.01
    _, velocity = command_to_pose(command, 0.01, 0.03, lead=0.01, last_heading=np.pi - 0.02)
    assert velocity[2] == pytest.approx(0.03 / 0.03)


def test_box_qp_refuses_a_singular_system():
    H = np.array([[1.0, 1.0], [1.0, 1.0]])
    with pytest.raises(np.linalg.LinAlgError), np.errstate(invalid="ignore"):
        solve_box_qp(H, np.array([1.0, 0.0]), np.full(2, -10.0), np.full(2, 10.0))
