"""The ``maxent_command`` estimator's likelihood for PBP's operator: a silent operator who
lets the robot go on toward a goal raises it, a turn toward a goal raises it, and passing
near a goal earns no more than moving straight at a far one. Expected values are
hand-computed from the definitions (docs/concepts/goal-estimators.md)."""

import math
import re

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from pbp_drake.core.hindsight_optimization import HopSettings, hop_targets, update_posterior
from pbp_drake.core.hindsight_optimization import uniform_log_belief
from pbp_drake.core.maxent_command import (
    intent_evidence, move_evidence, turn_evidence, update_intent_posterior)
from pbp_drake.systems import MaxEntGoalEstimator

SETTINGS = HopSettings()
SPEED = 0.12  # the operators' speed (m/s), the HSR tasks' nominal speed
DT = 0.1  # the published cost_time_step
FAR_SLOPE = 2.25 + 0.2  # alpha + c0, the value's slope beyond 7 cm
PERIOD = 0.03
# A ahead-left, B ahead-right, C behind: the hand at the origin heading along +x.
GOALS = np.array([[1.5, 0.6, 0.7], [1.5, -0.6, 0.7], [-1.0, 0.0, 0.7]])


def run_estimator(operator_speed, hand_velocity, command, active, ticks=40, heading=0.0):
    """The estimator's probabilities after `ticks` ticks of constant inputs, the hand at
    the origin (0, 0, 0.7)."""
    estimator = MaxEntGoalEstimator(len(GOALS), SETTINGS, PERIOD, operator_speed=operator_speed)
    context = estimator.CreateDefaultContext()
    estimator.get_ee_state_input_port().FixValue(
        context, [0.0, 0.0, 0.7, *hand_velocity, heading, 0.0])
    estimator.get_goals_input_port().FixValue(context, GOALS.reshape(-1))
    estimator.get_operator_command_input_port().FixValue(context, command)
    estimator.get_operator_active_input_port().FixValue(context, [1.0 if active else 0.0])
    simulator = Simulator(estimator, context)
    simulator.AdvanceTo(ticks * PERIOD - 1e-9)
    return estimator.get_goal_probabilities_output_port().Eval(context)


def toward(goal, speed=SPEED):
    direction = GOALS[goal] - [0.0, 0.0, 0.7]
    return speed * direction / np.linalg.norm(direction)


def test_a_silent_operator_letting_the_hand_go_on_toward_a_raises_a():
    probabilities = run_estimator(SPEED, toward(0), [0.0, 0.0, 0.0, 0.0], active=False)
    assert probabilities[0] > 0.5 > probabilities[1] > probabilities[2]  # C is behind
    # HOP's published update reads the silent operator as no evidence: the belief holds.
    published = run_estimator(None, toward(0), [0.0, 0.0, 0.0, 0.0], active=False)
    np.testing.assert_allclose(published, [1 / 3] * 3, atol=1e-12)


def test_a_turn_toward_b_raises_b():
    """Heading straight ahead, the operator turns right (negative yaw rate) without moving:
    B, on the right, gains on A (and C, behind, as much as B: turning right is the
    shorter way round to it too)."""
    probabilities = run_estimator(SPEED, np.zeros(3), [0.0, 0.0, 0.0, -0.8], active=True)
    assert probabilities[1] > 1 / 3 > probabilities[0]
    assert probabilities[1] > 2 * probabilities[0]
    published = run_estimator(None, np.zeros(3), [0.0, 0.0, 0.0, -0.8], active=True)
    np.testing.assert_allclose(published[:2], published[0], atol=1e-12)  # A and B alike


def test_the_turn_evidence_against_the_definition():
    """Heading 0, yaw rate 0.5 rad/s: over dt 0.1 s the heading turns 0.05 rad left. A goal
    at bearing pi/2 gets the whole turn, +(alpha + c0) s dt; one at bearing 0.02 rad is
    passed, |e| = 0.02 and |e'| = 0.03, so (0.02 - 0.03) / 0.05 = -0.2 of it; one at
    bearing -pi/2 the whole turn away; one straight below the hand nothing."""
    targets = hop_targets([[0.0, 1.0, 0.7], [1.0, math.tan(0.02), 0.7], [0.0, -1.0, 0.7],
                           [0.0, 0.0, 0.2]])
    evidence = turn_evidence(SETTINGS, targets, [0.0, 0.0, 0.7], 0.0, 0.5, SPEED)
    full = FAR_SLOPE * SPEED * DT
    np.testing.assert_allclose(evidence, [full, -0.2 * full, -full, 0.0], atol=1e-12)
    np.testing.assert_array_equal(
        turn_evidence(SETTINGS, targets, [0.0, 0.0, 0.7], 0.0, 0.0, SPEED), np.zeros(4))


def test_moving_far_from_every_goal_is_the_drop_of_the_linear_value():
    targets = hop_targets(GOALS)
    velocity = np.array([0.1, 0.05, 0.0])
    evidence = move_evidence(SETTINGS, targets, [0.0, 0.0, 0.7], velocity)
    after = np.array([0.0, 0.0, 0.7]) + velocity * DT
    expected = [FAR_SLOPE * (math.dist(g, [0.0, 0.0, 0.7]) - math.dist(g, after))
                for g in GOALS]
    np.testing.assert_allclose(evidence, expected, atol=1e-12)


@pytest.mark.parametrize("offset", [0.0, 0.01, 0.03, 0.06])
def test_passing_within_7_cm_of_c_earns_at_most_the_cap(offset):
    """The hand passes C sideways at `offset` m, at the operators' speed: per tick, C gains
    on a far goal ahead of the hand by at most (alpha + c0) |v| dt (0.0294 nats), the
    evidence of a step straight at a far goal; HOP's published update gives it up to
    alpha dt (0.225) for being near."""
    c_goal = [1.0, offset, 0.7]
    targets = hop_targets([c_goal, [1.0, 3.0, 0.7]])
    cap = FAR_SLOPE * SPEED * DT
    published_gain = 0.0
    for x in np.linspace(0.9, 1.1, 41):  # alongside C, from 10 cm before to 10 cm after
        position, velocity = [x, 0.0, 0.7], [SPEED, 0.0, 0.0]
        evidence = intent_evidence(SETTINGS, targets, position, velocity, SPEED).total
        assert evidence[0] - evidence[1] <= cap + 1e-12
        published = update_posterior(SETTINGS, targets, uniform_log_belief(2), position,
                                     velocity).log_belief
        published_gain = max(published_gain, published[0] - published[1])
    # The step cost's near-goal bonus, alpha dt (1 - offset / delta) at the closest point.
    assert published_gain > 2.25 * DT * (1 - offset / 0.07) - cap


@pytest.mark.parametrize("call, message", [
    (lambda: turn_evidence(SETTINGS, hop_targets(GOALS), [0.0, 0.0], 0.0, 0.5, SPEED),
     "position must be 3 finite numbers, got [0.0, 0.0]"),
    (lambda: turn_evidence(SETTINGS, hop_targets(GOALS), [0.0, 0.0, 0.7], math.nan, 0.5, SPEED),
     "heading and yaw_rate must be finite, got nan, 0.5"),
    (lambda: turn_evidence(SETTINGS, hop_targets(GOALS), [0.0, 0.0, 0.7], 0.0, 0.5, 0.0),
     "speed must be positive, got 0.0"),
    (lambda: update_intent_posterior(
        SETTINGS, hop_targets(GOALS), [0.0, 0.0], intent_evidence(
            SETTINGS, hop_targets(GOALS), [0.0, 0.0, 0.7], [0.1, 0.0, 0.0], SPEED)),
     "log_belief must be 3 finite numbers"),
    (lambda: MaxEntGoalEstimator(len(GOALS), SETTINGS, PERIOD, operator_speed=-SPEED),
     "operator_speed must be positive, got -0.12"),
])
def test_bad_input_is_refused_by_name(call, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        call()
