"""HOP's goal posterior and assistance, and predict-then-assist, against the equations of
Javdani et al. (2015, 2018) written out here goal by goal and target by target with plain
floats and SciPy's rotations: an oracle that shares no code with
`pbp_drake.core.hindsight_optimization`."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from scipy.special import logsumexp

from pbp_drake.core.hindsight_optimization import (
    HopSettings, assisted_command, blending_weights, hop_targets, uniform_log_belief,
    update_posterior)

SETTINGS = HopSettings()
TRANSLATION = (2.25, 0.07, 0.2)
ROTATION = (0.20, math.pi / 32, 0.01)
ROTATION_WEIGHT = 0.07
DT = 0.1


# ---------------------------------------------------------------------------------------------
# The oracle: the notes' equations, one goal and one target at a time.


def value(x, alpha, delta, c0):
    if x <= delta:
        return alpha / (2 * delta) * x * x + c0 * x
    return (alpha + c0) * x - alpha * delta / 2


def step_cost(x, alpha, delta, c0):
    return DT * (alpha + c0) if x > delta else DT * (alpha / delta * x + c0)


def slope(x, alpha, delta, c0):
    return alpha + c0 if x > delta else c0 + alpha / delta * x


def rotation_of(q):
    w, x, y, z = q
    return Rotation.from_quat([x, y, z, w])


def oracle_target(position, velocity, orientation, angular_velocity, target):
    """(Q, V, d, r, theta, rotation vector after the step) of one target."""
    target_position, target_orientation = target
    d = math.dist(position, target_position)
    r = [p + v * DT - g for p, v, g in zip(position, velocity, target_position)]
    q = step_cost(d, *TRANSLATION) + value(math.hypot(*r), *TRANSLATION)
    v = value(d, *TRANSLATION)
    theta = rotation_vector = None
    if target_orientation is not None:
        hand, goal = rotation_of(orientation), rotation_of(target_orientation)
        theta = (hand * goal.inv()).magnitude()
        turned = Rotation.from_rotvec(np.asarray(angular_velocity) * DT) * hand
        rotation_vector = (turned * goal.inv()).as_rotvec()
        theta_next = float(np.linalg.norm(rotation_vector))
        q += ROTATION_WEIGHT * (step_cost(theta, *ROTATION) + value(theta_next, *ROTATION))
        v += ROTATION_WEIGHT * value(theta, *ROTATION)
    return q, v, d, r, theta, rotation_vector


def oracle_goal(state, goal_targets):
    """Q_g, V_g and the best target's (d, r, theta, rotation vector)."""
    rows = [oracle_target(*state, target) for target in goal_targets]
    best = min(range(len(rows)), key=lambda i: (rows[i][0], i))
    return rows[best][0], min(row[1] for row in rows), rows[best][2:]


def oracle_posterior(log_prior, state, goals, clip=0.99):
    updated = [log_b - (q - v) for log_b, (q, v, _) in
               zip(log_prior, (oracle_goal(state, g) for g in goals))]
    probabilities = np.exp(np.array(updated) - logsumexp(updated))
    best = int(np.argmax(probabilities))
    if len(goals) > 1 and probabilities[best] > clip:
        excess = probabilities[best] - clip
        probabilities = probabilities + excess / (len(goals) - 1)
        probabilities[best] = clip
    return probabilities


def oracle_action(weights, state, goals):
    linear, angular = np.zeros(3), np.zeros(3)
    for weight, goal_targets in zip(weights, goals):
        _, _, (d, r, theta, rotation_vector) = oracle_goal(state, goal_targets)
        length = math.hypot(*r)
        if length > 0:
            gradient = slope(length, *TRANSLATION) * np.array(r) / length
            linear += weight * gradient * min(1.0, length / 0.02)
        if theta is not None:
            angle = float(np.linalg.norm(rotation_vector))
            gradient = ROTATION_WEIGHT * slope(angle, *ROTATION) * rotation_vector / angle
            angular += weight * gradient * min(1.0, angle / (math.pi / 12))
    return -linear / (sum(weights) * 40.0), -angular / (sum(weights) * 0.05)


# ---------------------------------------------------------------------------------------------
# Random states


def random_quaternion(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def random_problem(rng, with_orientations):
    """K goals with 1 to 3 targets each, a hand pose and an operator's command."""
    goal_count = int(rng.integers(1, 7))
    goals = []
    for _ in range(goal_count):
        goals.append([(rng.uniform(-1.0, 2.5, 3),
                       random_quaternion(rng) if with_orientations else None)
                      for _ in range(int(rng.integers(1, 4)))])
    # Some targets within the quadratic zone and the fade, some far.
    scale = rng.choice([0.01, 0.05, 1.0])
    anchor = goals[0][0][0]
    position = anchor + scale * rng.normal(size=3)
    state = (position, rng.normal(0.0, 0.12, 3),
             random_quaternion(rng) if with_orientations else None,
             rng.normal(0.0, 0.5, 3) if with_orientations else None)
    flat = [target for goal in goals for target in goal]
    targets = hop_targets(
        [p for p, _ in flat], [q for _, q in flat] if with_orientations else None,
        [g for g, goal in enumerate(goals) for _ in goal], goal_count)
    return goals, targets, state


@pytest.mark.parametrize("with_orientations", [False, True])
@pytest.mark.parametrize("seed", range(40))
def test_posterior_and_action_agree_with_the_equations(seed, with_orientations):
    rng = np.random.default_rng(seed)
    goals, targets, state = random_problem(rng, with_orientations)
    prior = np.log(rng.dirichlet(np.ones(len(goals))))
    update = update_posterior(SETTINGS, targets, prior, *state)
    expected = oracle_posterior(prior, state, goals)
    np.testing.assert_allclose(update.probabilities, expected, rtol=0, atol=1e-12)
    assert update.clipped == (np.max(expected) == 0.99 and len(goals) > 1)

    position, velocity, orientation, angular_velocity = state
    command = assisted_command("hop", SETTINGS, targets, update.probabilities, position,
                               velocity, orientation, angular_velocity)
    linear, angular = oracle_action(update.probabilities, state, goals)
    np.testing.assert_allclose(command.velocity, velocity + linear, rtol=0, atol=1e-12)
    if with_orientations:
        np.testing.assert_allclose(command.angular_velocity, angular_velocity + angular,
                                   rtol=0, atol=1e-12)
    else:
        assert command.angular_velocity is None


@pytest.mark.slow
def test_recursive_updates_agree_with_the_equations():
    """Fifty updates along a path, each from the last one's clipped belief."""
    rng = np.random.default_rng(7)
    goals, targets, _ = random_problem(rng, with_orientations=True)
    log_belief = uniform_log_belief(len(goals))
    expected = np.full(len(goals), 1.0 / len(goals))
    position, orientation = np.zeros(3), random_quaternion(rng)
    for _ in range(50):
        state = (position, rng.normal(0, 0.12, 3), orientation, rng.normal(0, 0.4, 3))
        update = update_posterior(SETTINGS, targets, log_belief, *state)
        expected = oracle_posterior(np.log(expected), state, goals)
        np.testing.assert_allclose(update.probabilities, expected, rtol=0, atol=1e-12)
        log_belief = update.log_belief
        position = position + state[1] * 0.03


def test_operator_heading_for_a_goal_makes_it_the_most_probable():
    targets = hop_targets([[1.5, 0.0, 0.7], [1.5, 1.2, 0.7], [0.0, 1.5, 0.7]])
    log_belief, position = uniform_log_belief(3), np.array([0.0, 0.0, 0.7])
    velocity, history = np.array([0.12, 0.0, 0.0]), []
    for _ in range(100):
        update = update_posterior(SETTINGS, targets, log_belief, position, velocity)
        log_belief, position = update.log_belief, position + velocity * 0.03
        history.append(update.probabilities[0])
    assert np.argmax(update.probabilities) == 0
    assert (np.diff(history) > 0).all() and history[-1] > 0.6


def test_certainty_sits_at_the_clip_and_the_excess_is_shared_evenly():
    targets = hop_targets([[1.0, 0.0, 0.7], [0.0, 2.0, 0.7], [0.0, -2.0, 0.7]])
    log_belief = uniform_log_belief(3)
    for _ in range(500):
        update = update_posterior(SETTINGS, targets, log_belief, [0.0, 0.0, 0.7],
                                  [0.12, 0.0, 0.0])
        log_belief = update.log_belief
    assert update.clipped
    assert update.probabilities[0] == pytest.approx(0.99, abs=1e-15)
    # The two others are symmetric: the spread excess leaves them equal.
    assert update.probabilities[1] == pytest.approx(update.probabilities[2], abs=1e-15)
    assert update.probabilities.sum() == pytest.approx(1.0, abs=1e-12)
    unclipped = update_posterior(HopSettings(max_probability=1.0), targets, log_belief,
                                 [0.0, 0.0, 0.7], [0.12, 0.0, 0.0])
    assert not unclipped.clipped and unclipped.probabilities[0] > 0.99


@pytest.mark.parametrize("distance", [1e-9, 1.0, 1e6])
def test_the_posterior_stays_finite_and_normalised_for_ten_thousand_goals(distance):
    rng = np.random.default_rng(3)
    directions = rng.normal(size=(10_000, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    position = np.array([0.5, 0.0, 0.7])
    targets = hop_targets(position + distance * directions)
    log_belief = uniform_log_belief(10_000)
    for _ in range(20):
        update = update_posterior(SETTINGS, targets, log_belief, position,
                                  rng.normal(0.0, 0.2, 3))
        log_belief = update.log_belief
        assert np.isfinite(update.log_belief).all()
        assert np.isfinite(update.probabilities).all()
        assert update.probabilities.sum() == pytest.approx(1.0, abs=1e-9)
    command = assisted_command("hop", SETTINGS, targets, update.probabilities, position,
                               [0.1, 0.0, 0.0])
    assert np.isfinite(command.velocity).all()


@pytest.mark.parametrize("distance", [1e-9, 1e6])
def test_a_goal_at_an_extreme_distance_keeps_the_posterior_finite(distance):
    position = np.array([0.0, 0.0, 0.7])
    targets = hop_targets([position + [distance, 0.0, 0.0], [0.0, 1.0, 0.7]])
    log_belief = uniform_log_belief(2)
    for step in range(200):
        update = update_posterior(SETTINGS, targets, log_belief, position,
                                  [0.2 * (-1) ** step, 0.1, 0.0])
        log_belief = update.log_belief
        assert np.isfinite(log_belief).all() and abs(update.probabilities.sum() - 1) < 1e-12


def test_with_one_goal_far_away_hop_adds_the_cost_gradient_step():
    """The operator's velocity plus (alpha + c0) / lambda = 0.06125 m/s toward the goal from
    where the operator's step leads."""
    goal = np.array([2.0, 1.0, 0.7])
    position, velocity = np.array([0.0, 0.0, 0.7]), np.array([0.05, -0.1, 0.0])
    command = assisted_command("hop", SETTINGS, hop_targets([goal]), [1.0], position,
                               velocity)
    after_step = position + velocity * DT
    toward = (goal - after_step) / np.linalg.norm(goal - after_step)
    np.testing.assert_allclose(command.velocity, velocity + 2.45 / 40.0 * toward,
                               rtol=0, atol=1e-15)


def test_with_one_goal_near_the_assistance_is_the_quadratic_slope_and_fades():
    goal = np.array([1.0, 0.0, 0.7])
    targets = hop_targets([goal])
    for gap in (0.05, 0.01):  # inside the quadratic zone; inside the 2 cm fade too
        position = goal - [gap, 0.0, 0.0]
        command = assisted_command("hop", SETTINGS, targets, [1.0], position, np.zeros(3))
        expected = (0.2 + 2.25 / 0.07 * gap) * min(1.0, gap / 0.02) / 40.0
        np.testing.assert_allclose(command.velocity, [expected, 0.0, 0.0], atol=1e-15)
    at_goal = assisted_command("hop", SETTINGS, targets, [1.0], goal, np.zeros(3))
    np.testing.assert_array_equal(at_goal.velocity, np.zeros(3))


def test_the_fade_reads_the_distance_after_the_operators_step():
    """5 cm short, the operator's step (0.4 m/s for 0.1 s) ends 1 cm short: the action is
    faded by 0.01 / 0.02 = 0.5, not by the present 0.05 / 0.02 (no fade). 1 cm short, a step
    of 0.3 m/s ends 2 cm past: no fade, and the action pulls back."""
    goal = np.array([1.0, 0.0, 0.7])
    targets = hop_targets([goal])
    slope_at = {0.01: 0.2 + 2.25 / 0.07 * 0.01, 0.02: 0.2 + 2.25 / 0.07 * 0.02}
    for short, speed, after, fade in ((0.05, 0.4, -0.01, 0.5), (0.01, 0.3, 0.02, 1.0)):
        command = assisted_command("hop", SETTINGS, targets, [1.0], goal - [short, 0, 0],
                                   [speed, 0.0, 0.0])
        action = -math.copysign(1.0, after) * slope_at[abs(after)] * fade / 40.0
        np.testing.assert_allclose(command.velocity, [speed + action, 0.0, 0.0],
                                   rtol=0, atol=1e-15)


def test_the_rotation_fade_reads_the_angle_after_the_operators_step():
    """pi/8 about z from the grasp, turning back pi/12 in the step: theta' = pi/24, beyond
    the quadratic zone (pi/32), so the slope is 0.2 + 0.01, faded by (pi/24) / (pi/12)."""
    hand = [math.cos(math.pi / 16), 0.0, 0.0, math.sin(math.pi / 16)]  # pi/8 about z
    turn = [0.0, 0.0, -(math.pi / 12) / DT]
    targets = hop_targets([[1.0, 0.0, 0.7]], [[1.0, 0.0, 0.0, 0.0]])
    command = assisted_command("hop", SETTINGS, targets, [1.0], [1.0, 0.0, 0.7],
                               np.zeros(3), hand, turn)
    action = -ROTATION_WEIGHT * (0.2 + 0.01) * 0.5 / 0.05
    np.testing.assert_allclose(command.angular_velocity, [0.0, 0.0, turn[2] + action],
                               rtol=0, atol=1e-12)
    np.testing.assert_array_equal(command.velocity, np.zeros(3))


@pytest.mark.parametrize("method", ["hop", "predict_then_assist"])
def test_with_the_assistance_off_the_command_is_the_operators_alone(method):
    """Certain of a goal 1 m away, the robot still adds nothing: the operator's command
    comes back as it went in, signed zeros included."""
    off = HopSettings(assistance=False)
    targets = hop_targets([[1.0, 0.0, 0.7], [0.0, 1.0, 0.7]], [[1.0, 0, 0, 0]] * 2)
    velocity, angular = np.array([-0.0, 0.1, 0.0]), np.array([0.0, -0.0, 0.3])
    command = assisted_command(method, off, targets, [0.99, 0.01], [0.0, 0.0, 0.7],
                               velocity, [1.0, 0.0, 0.0, 0.0], angular)
    assert not command.assisting
    for got, sent in ((command.velocity, velocity), (command.angular_velocity, angular)):
        np.testing.assert_array_equal(got, sent)
        np.testing.assert_array_equal(np.signbit(got), np.signbit(sent))
    on = assisted_command(method, SETTINGS, targets, [0.99, 0.01], [0.0, 0.0, 0.7],
                          velocity, [1.0, 0.0, 0.0, 0.0], angular)
    assert on.assisting and on.velocity[0] > 0.05


def test_predict_then_assist_passes_the_operator_through_below_the_threshold():
    targets = hop_targets([[1.0, 0.5, 0.7], [1.0, -0.5, 0.7], [0.0, 1.5, 0.7]])
    position, velocity = np.array([0.0, 0.0, 0.7]), np.array([0.1, 0.02, 0.0])
    for belief in ([0.5, 0.3, 0.2], [0.65, 0.25, 0.1], [0.34, 0.33, 0.33]):
        command = assisted_command("predict_then_assist", SETTINGS, targets, belief, position,
                                   velocity)
        np.testing.assert_array_equal(command.velocity, velocity)
        assert not command.assisting


def test_predict_then_assist_assists_fully_toward_the_most_probable_goal_above_it():
    targets = hop_targets([[1.0, 0.5, 0.7], [1.0, -0.5, 0.7], [0.0, 1.5, 0.7]])
    position, velocity = np.array([0.0, 0.0, 0.7]), np.array([0.1, 0.02, 0.0])
    belief = [0.1, 0.8, 0.1]
    blended = assisted_command("predict_then_assist", SETTINGS, targets, belief, position,
                               velocity)
    certain = assisted_command("hop", SETTINGS, targets, [0.0, 1.0, 0.0], position,
                               velocity)
    hedged = assisted_command("hop", SETTINGS, targets, belief, position, velocity)
    assert blended.assisting
    np.testing.assert_allclose(blended.velocity, certain.velocity, rtol=0, atol=1e-15)
    linear, _ = oracle_action([0.0, 1.0, 0.0], (position, velocity, None, None),
                              [[(g, None)] for g in targets.positions])
    np.testing.assert_allclose(blended.velocity, velocity + linear, rtol=0, atol=1e-12)
    # HOP hedges over the same belief: a different command.
    assert np.linalg.norm(hedged.velocity - blended.velocity) > 1e-3


def test_blending_weights_at_the_threshold_and_with_one_goal():
    assert blending_weights([0.7, 0.3], 0.4).tolist() == [0.0, 0.0]  # 0.4, not more
    assert blending_weights([0.71, 0.29], 0.4).tolist() == [1.0, 0.0]
    assert blending_weights([1.0], 0.4).tolist() == [1.0]


@pytest.mark.parametrize("field, value", [
    ("cost_time_step", 0.0), ("translation_gain", -1.0), ("translation_switch_distance", 0.0),
    ("translation_constant", math.nan), ("rotation_gain", 0.0), ("rotation_switch_angle", -0.1),
    ("rotation_constant", math.inf), ("rotation_weight", 0.0), ("translation_divisor", 0.0),
    ("rotation_divisor", -0.05), ("translation_fade_distance", 0.0),
    ("rotation_fade_angle", math.nan), ("max_probability", 0.0), ("max_probability", 1.5),
    ("max_probability", math.nan), ("blending_threshold", 1.0),
    ("blending_threshold", -0.1), ("cost_time_step", True), ("translation_gain", "2")])
def test_bad_settings_are_refused_naming_the_field(field, value):
    with pytest.raises(ValueError, match=field):
        HopSettings(**{field: value})


def test_bad_inputs_are_refused():
    targets = hop_targets([[1.0, 0.0, 0.7]])
    with pytest.raises(ValueError, match="velocity"):
        update_posterior(SETTINGS, targets, [0.0], [0, 0, 0.7], [math.nan, 0, 0])
    with pytest.raises(ValueError, match="orientation"):
        update_posterior(SETTINGS, hop_targets([[1, 0, 0.7]], [[1, 0, 0, 0]]), [0.0],
                         [0, 0, 0.7], [0, 0, 0])
    with pytest.raises(ValueError, match="every one of the 3 goals"):
        hop_targets([[1, 0, 0], [2, 0, 0]], goals=[0, 2], goal_count=3)


@pytest.mark.parametrize("call, message", [
    (lambda: hop_targets(np.zeros((0, 3))), r"target positions must be \(N, 3\) with N >= 1"),
    (lambda: hop_targets([[1.0, 0.0, math.inf]]), "target positions contain NaN or infinite"),
    (lambda: hop_targets([[1.0, 0.0, 0.7]], [[1, 0, 0, 0], [1, 0, 0, 0]]),
     r"target orientations must be \(N, 4\) with N = 1"),
    (lambda: hop_targets([[1.0, 0.0, 0.7]], goals=[0.5]), "one integer goal index per target"),
    (lambda: hop_targets([[1.0, 0.0, 0.7]], goals=[1], goal_count=1),
     r"goal indices must lie in \[0, 1\), got \[1\]"),
    (lambda: hop_targets([[1.0, 0.0, 0.7], [0.0, 1.0, 0.7]], goal_count=2.5),
     "goal_count must be a whole number >= 1, got 2.5"),
    (lambda: update_posterior(SETTINGS, hop_targets([[1.0, 0.0, 0.7]]), [0.0], [0, 0], [0, 0, 0]),
     "position must have 3 entries, got 2"),
    (lambda: update_posterior(SETTINGS, hop_targets([[1.0, 0.0, 0.7]]), [0.0, 0.0], [0, 0, 0.7],
                              [0, 0, 0]), "log_belief must be 1 finite numbers"),
    (lambda: assisted_command("hop", SETTINGS, hop_targets([[1.0, 0.0, 0.7]]), [math.nan],
                              [0, 0, 0.7], [0, 0, 0]), "goal_probabilities must be 1 finite"),
    (lambda: assisted_command("hop", SETTINGS, hop_targets([[1.0, 0.0, 0.7], [0.0, 1.0, 0.7]]),
                              np.log([0.5, 0.5]), [0, 0, 0.7], [0.1, 0, 0]),
     r"goal_probabilities must be 2 finite numbers >= 0 \(probabilities, not their logs\)"),
    (lambda: assisted_command("assist", SETTINGS, hop_targets([[1.0, 0.0, 0.7]]), [1.0],
                              [0, 0, 0.7], [0, 0, 0]), "method 'assist' is unknown; choose one"),
])
def test_bad_targets_beliefs_and_methods_are_refused_by_name(call, message):
    with pytest.raises(ValueError, match=message):
        call()
