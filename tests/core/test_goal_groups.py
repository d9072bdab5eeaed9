"""Goals the estimate cannot tell apart act as one (`core.goal_groups`, `GoalGrouping`): the
robot heads for their probability-weighted point and commits to a goal, and shows it, only
once the group allows or the hand has reached the point, and keeps the commitment while the
estimator selects that goal."""

import numpy as np
import pytest

from pbp_drake.core.goal_estimation import GoalEstimatorSettings
from pbp_drake.core.goal_groups import NO_GOAL, group_target, pose_group_target
from pbp_drake import GoalGrouping, PoseGoalGrouping

SETTINGS = dict(group_mass=0.9, commit_radius=0.05, commit_probability=0.5)  # 0.8 by default


def target(goals, probabilities, selected=None):
    probabilities = np.asarray(probabilities, float)
    selected = int(np.argmax(probabilities)) if selected is None else selected
    return group_target(np.asarray(goals, float), probabilities, selected, **SETTINGS)


def test_two_goals_equally_likely_are_headed_for_between_and_neither_is_shown():
    result = target([[1.0, 0.5, 0.7], [1.0, -0.5, 0.7], [3.0, 0.0, 0.7]], [0.48, 0.48, 0.04])
    np.testing.assert_allclose(result.point, [1.0, 0.0, 0.7])
    assert result.shown == NO_GOAL and result.size == 2


def test_the_point_weighs_each_goal_by_its_probability():
    goals = [[1.0, 0.0, 0.7], [2.0, 0.0, 0.7], [2.0, 1.0, 0.7], [1.0, -1.0, 0.7]]
    result = target(goals, [0.45, 0.35, 0.15, 0.05])
    # The group holds 0.95 of the mass (0.8 is short of 0.9): its three likely goals.
    assert result.size == 3
    np.testing.assert_allclose(result.point, np.array([0.45, 0.35, 0.15]) @ np.array(
        goals[:3]) / 0.95)


def test_a_likely_goal_is_committed_to_and_shown():
    goals = [[1.0, 0.5, 0.7], [1.0, -0.5, 0.7]]
    result = target(goals, [0.6, 0.4])
    assert result.shown == 0 and result.size == 1
    np.testing.assert_array_equal(result.point, goals[0])


def test_goals_closer_than_the_commit_radius_act_as_one():
    goals = [[1.5, 0.0, 0.7], [1.5, 0.03, 0.7], [1.5, -0.03, 0.7]]
    result = target(goals, [0.34, 0.33, 0.33], selected=1)
    assert result.shown == 1  # the estimator's selection, with its hysteresis
    np.testing.assert_array_equal(result.point, goals[1])


def test_ten_thousand_goals_group_to_the_likely_ones():
    rng = np.random.default_rng(0)
    goals = np.column_stack([rng.uniform(1.25, 2.5, 10_000), rng.uniform(-1, 1, 10_000),
                             np.full(10_000, 0.7)])
    logits = -np.abs(goals[:, 1] - 0.2) / 0.01  # the goals near y = 0.2 are likely
    probabilities = np.exp(logits - logits.max())
    probabilities /= probabilities.sum()
    result = target(goals, probabilities)
    assert result.shown == NO_GOAL and 1 < result.size < 1_000
    assert abs(result.point[1] - 0.2) < 0.02


@pytest.mark.parametrize("settings, message", [
    (dict(group_mass=1.0), "group_mass must lie in"),
    (dict(group_mass=float("nan")), "group_mass must lie in"),
    (dict(group_mass=-0.1), "group_mass must lie in"),
    (dict(commit_radius=0.0), "commit_radius must be a positive finite distance"),
    (dict(commit_radius=float("inf")), "commit_radius must be a positive finite distance"),
    (dict(commit_probability=0.0), "commit_probability must lie in"),
    (dict(commit_probability=True), "commit_probability must lie in"),
])
def test_a_setting_out_of_range_is_refused_naming_it(settings, message):
    with pytest.raises(ValueError, match=message):
        GoalEstimatorSettings(**{**SETTINGS, **settings})
    # Set after construction (as a YAML loader does), the system refuses it too.
    changed = GoalEstimatorSettings(**SETTINGS)
    for name, value in settings.items():
        setattr(changed, name, value)
    with pytest.raises(ValueError, match=message):
        GoalGrouping(3, changed, 0.03)


def test_the_hand_at_the_groups_point_commits_to_the_selected_goal():
    goals = [[1.0, 0.5, 0.7], [1.0, -0.5, 0.7], [3.0, 0.0, 0.7]]
    away = group_target(np.asarray(goals), np.array([0.48, 0.48, 0.04]), 1, **SETTINGS,
                        hand=np.array([0.5, 0.0, 0.7]))
    assert away.shown == NO_GOAL
    there = group_target(np.asarray(goals), np.array([0.48, 0.48, 0.04]), 1, **SETTINGS,
                         hand=np.array([1.0, 0.04, 0.7]))
    assert there.shown == 1
    np.testing.assert_array_equal(there.point, goals[1])


def test_a_commitment_holds_while_the_same_goal_is_selected():
    goals = np.array([[1.0, 0.5, 0.7], [1.0, -0.5, 0.7], [3.0, 0.0, 0.7]])
    probabilities = np.array([0.48, 0.48, 0.04])
    held = group_target(goals, probabilities, 1, **SETTINGS, committed=1)
    assert held.shown == 1
    # Another goal selected: the commitment is gone, the group is followed again.
    assert group_target(goals, probabilities, 0, **SETTINGS, committed=1).shown == NO_GOAL


def fixed_grouping(goals, probabilities, selected, hand):
    system = GoalGrouping(len(goals), GoalEstimatorSettings(**SETTINGS), 0.03)
    context = system.CreateDefaultContext()
    system.get_goals_input_port().FixValue(context, np.asarray(goals, float).reshape(-1))
    system.get_goal_probabilities_input_port().FixValue(context, probabilities)
    system.get_selected_goal_input_port().FixValue(context, [float(selected)])
    system.get_ee_state_input_port().FixValue(context, np.concatenate([hand, np.zeros(5)]))
    return system, context


def test_the_system_keeps_its_commitment_when_the_hand_leaves_the_groups_point():
    goals = [[1.0, 0.5, 0.7], [1.0, -0.5, 0.7], [3.0, 0.0, 0.7]]
    system, context = fixed_grouping(goals, [0.48, 0.48, 0.04], 1, [1.0, 0.0, 0.7])
    assert system.get_shown_goal_output_port().Eval(context)[0] == 1
    # The tick's update keeps the commitment in the state ...
    context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context).value())
    # ... so the hand heading on to the goal, away from the point, still shows it.
    system.get_ee_state_input_port().FixValue(context, np.array([1.0, -0.3, 0.7, 0, 0, 0, 0,
                                                                 0]))
    assert system.get_shown_goal_output_port().Eval(context)[0] == 1
    np.testing.assert_array_equal(
        system.get_followed_goals_output_port().Eval(context).reshape(3, 3)[1], goals[1])


def test_the_system_moves_the_selected_goals_row_and_shows_none_until_committed():
    goals = np.array([[1.0, 0.5, 0.7], [1.0, -0.5, 0.7], [3.0, 0.0, 0.7]])
    system = GoalGrouping(3, GoalEstimatorSettings(**SETTINGS), 0.03)
    context = system.CreateDefaultContext()
    system.get_ee_state_input_port().FixValue(context, np.zeros(8))
    system.get_goals_input_port().FixValue(context, goals.reshape(-1))
    system.get_goal_probabilities_input_port().FixValue(context, [0.48, 0.48, 0.04])
    system.get_selected_goal_input_port().FixValue(context, [1.0])
    followed = system.get_followed_goals_output_port().Eval(context).reshape(3, 3)
    np.testing.assert_allclose(followed[1], [1.0, 0.0, 0.7])
    np.testing.assert_array_equal(followed[[0, 2]], goals[[0, 2]])
    assert system.get_shown_goal_output_port().Eval(context)[0] == NO_GOAL
    system.get_goal_probabilities_input_port().FixValue(context, [0.2, 0.7, 0.1])
    np.testing.assert_array_equal(
        system.get_followed_goals_output_port().Eval(context).reshape(3, 3), goals)
    assert system.get_shown_goal_output_port().Eval(context)[0] == 1


# Grasp poses `[x, y, z, qw, qx, qy, qz]`: two grasps of one object 45 degrees apart about z,
# and one of an object far away; the task's 3 cm per 10 degrees.
EIGHTH = np.array([np.cos(np.pi / 8), 0.0, 0.0, np.sin(np.pi / 8)])
POSES = np.array([[1.0, 0.0, 0.7, 1.0, 0.0, 0.0, 0.0],
                  [1.0, 0.0, 0.7, *EIGHTH],
                  [2.0, 1.0, 0.7, 1.0, 0.0, 0.0, 0.0]])
METRES_PER_RADIAN = 0.03 / np.radians(10.0)


def pose_target(probabilities, selected=0, **keywords):
    return pose_group_target(POSES, np.asarray(probabilities, float), selected, **SETTINGS,
                             metres_per_radian=METRES_PER_RADIAN, **keywords)


def test_two_grasps_of_one_object_are_headed_for_at_their_mean_orientation():
    result = pose_target([0.48, 0.48, 0.04])
    assert result.shown == NO_GOAL and result.size == 2
    # Half way (22.5 degrees about z), at their shared position.
    np.testing.assert_allclose(result.point, [1.0, 0.0, 0.7, np.cos(np.pi / 16), 0.0, 0.0,
                                              np.sin(np.pi / 16)], atol=1e-12)
    # A quaternion's sign does not move the mean.
    flipped = POSES.copy()
    flipped[1, 3:] *= -1.0
    again = pose_group_target(flipped, np.array([0.48, 0.48, 0.04]), 0, **SETTINGS,
                              metres_per_radian=METRES_PER_RADIAN)
    np.testing.assert_allclose(again.point, result.point, atol=1e-12)


def test_the_hand_at_the_selected_grasp_or_at_the_groups_pose_commits():
    probabilities = [0.48, 0.48, 0.04]
    assert pose_target(probabilities, hand=np.array([0.5, 0.0, 0.7, 1, 0, 0, 0])).shown == (
        NO_GOAL)
    # At the selected grasp's position, turned 5 degrees off it: within 5 cm of pose error.
    turned = np.array([np.cos(np.radians(2.5)), 0.0, 0.0, np.sin(np.radians(2.5))])
    assert pose_target(probabilities, hand=np.array([1.02, 0.0, 0.7, *turned])).shown == 0
    # At the right place but 45 degrees off: that is another grasp, no commitment.
    assert pose_target(probabilities, selected=0,
                       hand=np.array([1.0, 0.0, 0.7, *EIGHTH])).shown == NO_GOAL


def test_grasps_that_act_as_one_with_the_selected_commit_together():
    near = POSES.copy()
    near[1, 3:] = [np.cos(np.radians(2.0)), 0.0, 0.0, np.sin(np.radians(2.0))]  # 4 degrees
    result = pose_group_target(near, np.array([0.45, 0.4, 0.15]), 0, **SETTINGS,
                               metres_per_radian=METRES_PER_RADIAN)
    # Neither holds the commit probability (0.5) alone; together they do.
    assert result.shown == 0
    np.testing.assert_array_equal(result.point, near[0])


def test_the_pose_system_moves_the_selected_grasps_row_and_shows_none_until_committed():
    system = PoseGoalGrouping(3, GoalEstimatorSettings(**SETTINGS), 0.03, METRES_PER_RADIAN)
    context = system.CreateDefaultContext()
    system.get_goal_poses_input_port().FixValue(context, POSES.reshape(-1))
    system.get_goal_probabilities_input_port().FixValue(context, [0.48, 0.48, 0.04])
    system.get_selected_goal_input_port().FixValue(context, [1.0])
    system.get_hand_pose_input_port().FixValue(context, np.concatenate(
        [[0.0, 0.0, 0.7, 1.0], np.zeros(9)]))
    followed = system.get_followed_poses_output_port().Eval(context).reshape(3, 7)
    np.testing.assert_allclose(followed[1], pose_target([0.48, 0.48, 0.04], 1).point)
    np.testing.assert_array_equal(followed[[0, 2]], POSES[[0, 2]])
    assert system.get_shown_goal_output_port().Eval(context)[0] == NO_GOAL
    with pytest.raises(ValueError, match="metres_per_radian must be a finite number >= 0"):
        PoseGoalGrouping(3, GoalEstimatorSettings(**SETTINGS), 0.03, float("nan"))
