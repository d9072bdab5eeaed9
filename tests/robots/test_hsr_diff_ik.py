"""The station's own diff IK pieces, alone: the box-constrained QP and the command's ramp."""

import numpy as np
import pytest
from pydrake.math import RigidTransform, RotationMatrix

from pbp_drake.robots.hsr_diff_ik import solve_box_qp
from pbp_drake.robots.hsr_ee_systems import EeCommandToPose


@pytest.mark.parametrize("seed", range(20))
def test_box_qp_meets_the_optimality_conditions(seed):
    rng = np.random.default_rng(seed)
    n = 9
    A = rng.normal(size=(n, n))
    H = A @ A.T + 0.1 * np.eye(n)
    g = rng.normal(size=n) * 5
    lower = -rng.uniform(0.0, 1.0, n)
    upper = rng.uniform(0.0, 1.0, n)
    lower[0] = upper[0] = 0.3  # a variable held fixed
    x = solve_box_qp(H, g, lower, upper)
    assert np.all(x >= lower) and np.all(x <= upper)
    gradient = H @ x - g
    tolerance = 1e-9 * np.abs(g).max()
    free = (x > lower) & (x < upper)
    assert np.all(np.abs(gradient[free]) < tolerance)
    assert np.all(gradient[(x <= lower) & (lower < upper)] > -tolerance)
    assert np.all(gradient[(x >= upper) & (lower < upper)] < tolerance)


def test_box_qp_without_active_bounds_is_the_unconstrained_minimum():
    H = np.diag([1.0, 2.0])
    x = solve_box_qp(H, np.array([0.5, 1.0]), np.full(2, -10.0), np.full(2, 10.0))
    np.testing.assert_allclose(x, [0.5, 0.5])


def pose_at(command, time, command_period, lead):
    system = EeCommandToPose(RotationMatrix(), command_period, lead)
    context = system.CreateDefaultContext()
    context.SetTime(time)
    system.get_ee_command_input_port().FixValue(context, command)
    return system.get_pose_output_port().Eval(context)


def test_command_to_pose_reads_the_ramp_lead_ahead():
    # [p, v, heading]: to be at p = 1 at the next tick, moving at 0.3 m/s along x.
    command = np.array([1.0, 0.0, 0.7, 0.3, 0.0, 0.0, 0.0])
    # Inside a tick (0.03 s), the ramp into p read 0.01 s ahead of 0.01 s.
    pose = pose_at(command, 0.01, 0.03, lead=0.01)
    np.testing.assert_allclose(pose.translation(), [1.0 - 0.3 * 0.01, 0.0, 0.7])
    # At the tick itself the command is still the last tick's: it carries on at v.
    pose = pose_at(command, 0.03, 0.03, lead=0.01)
    np.testing.assert_allclose(pose.translation(), [1.0 + 0.3 * 0.01, 0.0, 0.7])
    # Without a control period, p carried on at v for lead.
    pose = pose_at(command, 0.01, None, lead=0.01)
    np.testing.assert_allclose(pose.translation(), [1.003, 0.0, 0.7])
    assert isinstance(pose, RigidTransform)
