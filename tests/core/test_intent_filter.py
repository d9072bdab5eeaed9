"""The ``intent_filter`` estimator's math (`pbp_drake.core.intent_filter`) against its
definition written out goal by goal in plain Python, its hazard as a floor, a silence's
drift back to the heading, its clip, its settings' checks, and runaway confidence measured on
the scripted operator who first heads for a wrong object (`pbp_drake_bench.runaway`)."""

import math

import numpy as np
import pytest

from pbp_drake.core.intent_filter import (
    IntentFeatures, IntentFilterSettings, filter_step, intent_features, pose_intent_features,
    switch_probability)
from pbp_drake.core.quaternion import exp_map
from pbp_drake_bench import runaway

PERIOD = 0.03
GOALS = np.array([[1.0, 0.0, 0.7], [0.0, 1.0, 0.7], [-1.0, 0.0, 0.7], [0.5, 0.5, 0.7],
                  [0.0, 0.0, 0.2]])
HAND = np.array([0.0, 0.0, 0.7])


def test_a_motion_and_a_heading_straight_at_a_goal_score_one_and_away_minus_one():
    features = intent_features(GOALS, HAND, np.array([0.1, 0.0, 0.0]), 0.0, 0.0, PERIOD, 0.01)
    # Linear in the angle: 45 degrees off is half way between straight at and across.
    np.testing.assert_allclose(features.moves[:4], [1.0, 0.0, -1.0, 0.5], atol=1e-12)
    np.testing.assert_allclose(features.headings, [1.0, 0.0, -1.0, 0.5, 1.0], atol=1e-12)
    # The goal straight below: no bearing (the hand is at it on the floor), a motion across.
    assert features.moves[4] == pytest.approx(0.0)
    np.testing.assert_array_equal(features.turns, np.zeros(5))


def test_a_motion_slower_than_min_speed_has_no_direction():
    features = intent_features(GOALS, HAND, np.array([0.005, 0.0, 0.0]), 0.0, 0.0, PERIOD,
                               0.01)
    np.testing.assert_array_equal(features.moves, np.zeros(5))


def test_a_turn_toward_a_goal_scores_one_and_away_minus_one():
    # Turning counter-clockwise from +x: toward the goal at +y, away from none at -y.
    features = intent_features(GOALS, HAND, np.zeros(3), 0.0, 0.5, PERIOD, 0.01)
    assert features.turns[1] == pytest.approx(1.0)
    assert features.turns[3] == pytest.approx(1.0)
    assert features.turns[4] == 0.0  # no bearing
    # The goal dead ahead: any turn is away from it.
    assert features.turns[0] == pytest.approx(-1.0)
    away = intent_features(GOALS, HAND, np.zeros(3), 0.0, -0.5, PERIOD, 0.01)
    assert away.turns[1] == pytest.approx(-1.0)


# Grasp poses: ahead, left and above the hand, turned about z by 0, +0.5 and -0.5 rad; the
# hand at the origin, its approach axis (z_H of the identity) straight up.
POSES = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
TURNS = np.array([exp_map(np.array([0.0, 0.0, angle])) for angle in (0.0, 0.5, -0.5)])
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def pose_features(velocity=np.zeros(3), angular_velocity=np.zeros(3), **keywords):
    return pose_intent_features(POSES, TURNS, np.zeros(3), IDENTITY, velocity,
                                angular_velocity, PERIOD, 0.01, **keywords)


def test_a_pose_turn_toward_a_grasp_orientation_scores_one_and_away_minus_one():
    features = pose_features(angular_velocity=np.array([0.0, 0.0, 0.4]))
    np.testing.assert_allclose(features.turns, [-1.0, 1.0, -1.0], atol=1e-9)
    # The heading: the orientation's straightness and where the approach axis points (up).
    np.testing.assert_allclose(features.headings, [0.5, 0.5 * (1 - 1 / math.pi),
                                                   0.5 * (2 - 1 / math.pi)], atol=1e-12)
    np.testing.assert_array_equal(pose_features().turns, np.zeros(3))


def test_a_pose_motion_is_read_in_3d_and_without_the_forward_key_across_the_approach():
    upward = pose_features(velocity=np.array([0.0, 0.0, 0.1]))
    np.testing.assert_allclose(upward.moves, [0.0, 0.0, 1.0], atol=1e-12)
    # Without the forward key the operator cannot push along z_H (up): heading for the
    # grasp above, it sends nothing; for the one ahead, its whole direction is across.
    across = pose_features(velocity=np.array([0.1, 0.0, 0.0]), forward_key=False)
    np.testing.assert_allclose(across.moves, [1.0, 0.0, 0.0], atol=1e-12)
    # A silent operator's motion is the robot's, read whole.
    silent = pose_features(velocity=np.array([0.0, 0.0, 0.1]), forward_key=False, acts=False)
    np.testing.assert_allclose(silent.moves, [0.0, 0.0, 1.0], atol=1e-12)


def test_acting_while_a_goal_is_shown_is_evidence_against_it():
    assert pose_features(shown=1).overridden == 1
    assert pose_features(shown=1, acts=False).overridden == -1  # silent: no intervention
    assert pose_features(shown=-1).overridden == -1
    settings = IntentFilterSettings(heading_weight=0.0, override_rate=10.0)
    uniform = np.log(np.full(3, 1.0 / 3.0))
    update = filter_step(settings, uniform, pose_features(shown=1), PERIOD)
    assert update.probabilities[1] < update.probabilities[0] == pytest.approx(
        update.probabilities[2])
    unshown = filter_step(settings, uniform, pose_features(), PERIOD)
    np.testing.assert_allclose(unshown.probabilities, 1.0 / 3.0)


def _normalised_and_clipped(weights, max_probability):
    total = sum(weights)
    posterior = [weight / total for weight in weights]
    best = max(range(len(posterior)), key=lambda goal: posterior[goal])
    if posterior[best] > max_probability:
        excess = posterior[best] - max_probability
        posterior = [p + excess / (len(posterior) - 1) for p in posterior]
        posterior[best] = max_probability
    return posterior


def _by_hand(settings, belief, features):
    """The update written out goal by goal: the hazard, the motion's and the turn's
    evidence (the silence's while silent) into the belief, then the heading on top."""
    count = len(belief)
    hazard = 1.0 - math.exp(-settings.switch_rate * PERIOD)
    weights = []
    for goal in range(count):
        prior = (1.0 - hazard) * belief[goal] + hazard / count
        if features.acts:
            rate = (settings.move_rate * features.moves[goal]
                    + settings.turn_rate * features.turns[goal])
            if goal == features.overridden:
                rate -= settings.override_rate
        else:
            rate = settings.silence_rate * features.moves[goal]
        weights.append(prior * math.exp(PERIOD * rate))
    belief = _normalised_and_clipped(weights, settings.max_probability)
    pointed = [belief[goal] * math.exp(settings.heading_weight * features.headings[goal])
               for goal in range(count)]
    return belief, _normalised_and_clipped(pointed, settings.max_probability)


@pytest.mark.parametrize("acts", [True, False])
def test_a_step_is_the_hazard_the_evidence_the_clip_and_the_heading_on_top(acts):
    settings = IntentFilterSettings(move_rate=30.0, heading_weight=2.0, turn_rate=20.0,
                                    silence_rate=10.0, override_rate=15.0, switch_rate=0.4,
                                    max_probability=0.9)
    rng = np.random.default_rng(4)
    belief = [1.0 / len(GOALS)] * len(GOALS)
    log_belief = np.log(belief)
    clipped_once = False
    for _ in range(60):
        features = IntentFeatures(*rng.uniform(-1.0, 1.0, (3, len(GOALS))), acts,
                                  int(rng.integers(-1, len(GOALS))))
        belief, expected = _by_hand(settings, belief, features)
        update = filter_step(settings, log_belief, features, PERIOD)
        np.testing.assert_allclose(np.exp(update.log_belief), belief, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(update.probabilities, expected, rtol=1e-12, atol=1e-15)
        assert update.clipped == (max(expected) == settings.max_probability)
        clipped_once |= update.clipped
        log_belief = update.log_belief
    assert clipped_once


@pytest.mark.slow
def test_the_hazard_is_a_floor_no_evidence_pushes_a_goal_under():
    settings = IntentFilterSettings(move_rate=200.0, heading_weight=0.0, turn_rate=0.0,
                                    switch_rate=0.5, max_probability=1.0)
    log_belief = np.log(np.full(len(GOALS), 1.0 / len(GOALS)))
    toward_first = intent_features(GOALS, HAND, np.array([0.1, 0.0, 0.0]), 0.0, 0.0,
                                   PERIOD, 0.01)
    hazard = switch_probability(settings, PERIOD)
    for _ in range(2000):
        update = filter_step(settings, log_belief, toward_first, PERIOD)
        log_belief = update.log_belief
    # Each tick the goals behind gain at least h / K before the evidence against them.
    floor = hazard / len(GOALS) * math.exp(-2 * PERIOD * settings.move_rate)
    assert update.probabilities.min() >= 0.5 * floor
    assert update.probabilities[0] > 0.99


def test_a_silence_is_no_evidence_and_the_belief_drifts_back_to_the_heading():
    """With the shipped settings (no silence weight): evidence for the first goal, then
    silence while the robot moves toward the third; the belief returns to uniform at the
    switch rate, and the probabilities to what the heading alone says."""
    settings = IntentFilterSettings()
    log_belief = np.log(np.full(len(GOALS), 1.0 / len(GOALS)))
    acting = intent_features(GOALS, HAND, np.array([0.1, 0.0, 0.0]), math.pi / 2, 0.0,
                             PERIOD, 0.01)
    for _ in range(30):
        log_belief = filter_step(settings, log_belief, acting, PERIOD).log_belief
    assert np.argmax(log_belief) == 0
    silent = intent_features(GOALS, HAND, np.array([-0.1, 0.0, 0.0]), math.pi / 2, 0.0,
                             PERIOD, 0.01, acts=False)
    for _ in range(int(20.0 / PERIOD)):
        update = filter_step(settings, log_belief, silent, PERIOD)
        log_belief = update.log_belief
    np.testing.assert_allclose(np.exp(log_belief), 1.0 / len(GOALS), rtol=1e-3)
    heading_alone = np.exp(settings.heading_weight * silent.headings)
    np.testing.assert_allclose(update.probabilities, heading_alone / heading_alone.sum(),
                               rtol=1e-3)
    assert np.argmax(update.probabilities) == 1  # the hand points at +y


@pytest.mark.parametrize("field, value, message", [
    ("move_rate", -1.0, "intent_filter.move_rate must be a finite number >= 0"),
    ("heading_weight", float("nan"), "intent_filter.heading_weight must be a finite number"),
    ("silence_rate", -2.0, "intent_filter.silence_rate must be a finite number >= 0"),
    ("override_rate", float("nan"), "intent_filter.override_rate must be a finite number"),
    ("turn_rate", True, "intent_filter.turn_rate must be a finite number"),
    ("switch_rate", float("inf"), "intent_filter.switch_rate must be a finite number"),
    ("max_probability", 0.0, "intent_filter.max_probability must lie in (0, 1]"),
    ("max_probability", 1.5, "intent_filter.max_probability must lie in (0, 1]"),
    ("min_speed", -0.1, "intent_filter.min_speed must be a finite number >= 0"),
])
def test_bad_settings_name_the_field(field, value, message):
    settings = IntentFilterSettings(**{field: value})
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace("]", r"\]")):
        settings.validate()


@pytest.mark.slow
def test_the_filter_recovers_from_a_wrong_goal_held_long_in_bounded_time():
    """Runaway confidence: however long the operator held the wrong object (2 to 20 s),
    the filter names the target for good within half a second of the turn, and holding
    longer never makes it slower; HOP's published posterior, which has no hazard, takes
    seconds."""
    recoveries = [runaway.measure("intent_filter", hold).recovery for hold in runaway.HOLDS]
    assert all(recovery is not None and recovery <= 0.5 for recovery in recoveries)
    assert recoveries[-1] <= recoveries[0]
    hop = [runaway.measure("hop", hold).recovery for hold in runaway.HOLDS]
    assert all(recovery > 2.0 for recovery in hop)


def test_the_script_heads_for_the_wrong_object_then_reaches_the_target():
    ticks = runaway.script(5.0)
    turn = int(round(5.0 / runaway.PERIOD))
    assert {tick.goal for tick in ticks[:turn]} == {runaway.WRONG}
    assert {tick.goal for tick in ticks[turn:]} == {runaway.TARGET}
    assert np.linalg.norm(ticks[-1].position - runaway.OBJECTS[runaway.TARGET]) <= \
        runaway.ARRIVED + 0.01
