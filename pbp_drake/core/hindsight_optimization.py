"""Shared autonomy by hindsight optimization (HOP) and its predict-then-assist variant, in
pure NumPy: the goal posterior that reads the operator's command, and the assistance it gives.

Sources: Javdani, Srinivasa, Bagnell, RSS 2015; Javdani et al., IJRR 2018. Goal g (one of K)
has one or more targets kappa (N in all) with Huber-like costs; the posterior is
`log b_t(g) = log b_{t-1}(g) - (Q_g - V_g)`, normalised and clipped, and HOP commands
`u + a`, `a = -(1 / lambda) (sum_g b_g grad Q_g) / (sum_g b_g)`. The equations, the published
constants (`HopSettings`' defaults) and predict-then-assist:
docs/concepts/hindsight-optimization.md."""

import dataclasses
import math
import typing

import numpy as np

from pbp_drake.core import quaternion
from pbp_drake.core.choices import unknown_choice
from pbp_drake.core.coordinates import is_real, is_whole

# Below this (m, rad) the hand is at a target: no direction to it.
AT_TARGET = 1e-12


@dataclasses.dataclass
class HopSettings:
    """The cost model, posterior and assistance of HOP (scenario files: the `hop` section),
    read by the ``hop`` and ``predict_then_assist`` methods and the ``maxent_command`` goal
    estimator. Each default is the published constant. `cost_time_step` is the cost
    model's step, not the control period (docs/concepts/hindsight-optimization.md, "The
    cost model's step, the control tick and the operator's speed")."""

    #: The cost model's time step dt (s): a step costs dt times the cost's slope, and the
    #: operator's command is applied for dt to find the distance after it (published: 0.1).
    cost_time_step: float = 0.1
    #: Translation: the Huber cost's gain alpha (per m); far from a target its value grows
    #: by translation_gain + translation_constant per metre.
    translation_gain: float = 2.25
    #: Translation: the distance delta (m) within which the cost is quadratic.
    translation_switch_distance: float = 0.07
    #: Translation: the constant cost c0 (per m).
    translation_constant: float = 0.2
    #: Rotation, on the angle to a target's orientation: the gain alpha (per rad).
    rotation_gain: float = 0.20
    #: Rotation: the angle delta (rad) within which the cost is quadratic (pi/32).
    rotation_switch_angle: float = math.pi / 32
    #: Rotation: the constant cost c0 (per rad).
    rotation_constant: float = 0.01
    #: The rotation terms' weight against the translation's (a factor).
    rotation_weight: float = 0.07
    #: The translational assistance is the belief-weighted cost gradient over this
    #: (lambda; the assistance in m/s).
    translation_divisor: float = 40.0
    #: The rotational assistance's lambda (the assistance in rad/s).
    rotation_divisor: float = 0.05
    #: Each goal's translational assistance fades in proportion within this distance (m)
    #: of its target.
    translation_fade_distance: float = 0.02
    #: Each goal's rotational assistance fades in proportion within this angle (rad) of its
    #: target's orientation (pi/12).
    rotation_fade_angle: float = math.pi / 12
    #: The goal posterior's largest probability is clipped at this (a probability in
    #: (0, 1]; 1: never); the excess is spread evenly over the other goals.
    max_probability: float = 0.99
    #: predict_then_assist: the operator's command passes through while the two most probable
    #: goals differ by at most this (a probability in [0, 1)); beyond, full assistance.
    blending_threshold: float = 0.4
    #: False: the robot adds nothing: HOP's and predict_then_assist's command is the
    #: operator's alone (exactly teleop's); the posterior still runs.
    assistance: bool = True

    def __post_init__(self):
        self.validate()

    def validate(self):
        """Raises ValueError naming the first field that cannot be used (a YAML loader sets
        the fields after construction, so `resolve` calls this again)."""
        if not isinstance(self.assistance, bool):
            raise ValueError(f"assistance must be true or false, got {self.assistance!r}")
        numbers = [field.name for field in dataclasses.fields(self) if field.name != "assistance"]
        for name in numbers:
            value = getattr(self, name)
            if not is_real(value) or not math.isfinite(value):
                raise ValueError(f"{name} must be a finite number, got {value!r}")
        for name in numbers:
            if name not in ("max_probability", "blending_threshold") and not getattr(
                    self, name) > 0.0:
                raise ValueError(f"{name} must be positive, got {getattr(self, name)!r}")
        if not 0.0 < self.max_probability <= 1.0:
            raise ValueError(f"max_probability must lie in (0, 1], got "
                             f"{self.max_probability!r}")
        if not 0.0 <= self.blending_threshold < 1.0:
            raise ValueError(f"blending_threshold must lie in [0, 1), got "
                             f"{self.blending_threshold!r}")


class HopTargets(typing.NamedTuple):
    """The N targets of K goals: `positions` (N, 3), `orientations` (N, 4) unit quaternions
    or None (position only), `goals` (N,) the goal index of each target, `goal_count` K."""

    positions: np.ndarray
    orientations: typing.Optional[np.ndarray]
    goals: np.ndarray
    goal_count: int


def hop_targets(positions, orientations=None, goals=None, goal_count=None):
    """Checked `HopTargets`. `goals=None`: one target per goal, target i of goal i. Raises
    ValueError for NaN or infinite positions, orientations that are not unit quaternions,
    a goal index out of range or a goal without a target."""
    positions = np.array(positions, dtype=float)
    if positions.ndim != 2 or positions.shape[1] != 3 or len(positions) == 0:
        raise ValueError(f"target positions must be (N, 3) with N >= 1, got shape "
                         f"{positions.shape}")
    if not np.isfinite(positions).all():
        raise ValueError("target positions contain NaN or infinite values")
    if orientations is not None:
        orientations = quaternion.unit_quaternions(orientations, "target orientations")
        if orientations.shape != (len(positions), 4):
            raise ValueError(f"target orientations must be (N, 4) with N = {len(positions)},"
                             f" got shape {orientations.shape}")
    if goals is None:
        goals = np.arange(len(positions))
    goals = np.asarray(goals)
    if goals.shape != (len(positions),) or not np.issubdtype(goals.dtype, np.integer):
        raise ValueError(f"goals must be one integer goal index per target ({len(positions)}),"
                         f" got {goals!r}")
    if goal_count is not None and not is_whole(goal_count, 1):
        raise ValueError(f"goal_count must be a whole number >= 1, got {goal_count!r}")
    count = int(goals.max()) + 1 if goal_count is None else int(goal_count)
    if (goals < 0).any() or (goals >= count).any():
        raise ValueError(f"goal indices must lie in [0, {count}), got {goals.tolist()}")
    if len(np.unique(goals)) != count:
        raise ValueError(f"every one of the {count} goals needs a target")
    return HopTargets(positions, orientations, goals.astype(int), count)


# ---------------------------------------------------------------------------------------------
# The Huber cost of one term


def huber_value(x, gain, switch, constant):
    """`V(x)`: `(gain / (2 switch)) x^2 + constant x` up to `switch`, then
    `(gain + constant) x - gain switch / 2` (continuous, with a continuous slope)."""
    x = np.asarray(x, dtype=float)
    near = np.minimum(x, switch)  # no square of a far distance: it could overflow
    return np.where(x <= switch, gain / (2.0 * switch) * near * near + constant * near,
                    (gain + constant) * x - 0.5 * gain * switch)


def huber_slope(x, gain, switch, constant):
    """`V'(x)`: `(gain / switch) x + constant` up to `switch`, `gain + constant` beyond."""
    x = np.asarray(x, dtype=float)
    return np.where(x > switch, gain + constant, gain / switch * np.minimum(x, switch)
                    + constant)


def huber_step_cost(x, gain, switch, constant, time_step):
    """`c(x) = time_step V'(x)`: the cost of one step of the cost model at `x`."""
    return time_step * huber_slope(x, gain, switch, constant)


def _translation(settings):
    return (settings.translation_gain, settings.translation_switch_distance,
            settings.translation_constant)


def _rotation(settings):
    return settings.rotation_gain, settings.rotation_switch_angle, settings.rotation_constant


# ---------------------------------------------------------------------------------------------
# Per target and per goal


class TargetGeometry(typing.NamedTuple):
    """Where the hand stands to each of N targets now and after the operator's step:
    `distances` d (N,), `next_offsets` r = p' - p_kappa (N, 3); with orientations
    `angles` theta (N,) and `next_rotations` Log(q' q_kappa*) (N, 3), else None."""

    distances: np.ndarray
    next_offsets: np.ndarray
    angles: typing.Optional[np.ndarray]
    next_rotations: typing.Optional[np.ndarray]


def _finite_vector(value, name, size=3):
    value = np.asarray(value, dtype=float).reshape(-1)
    if value.size != size:
        raise ValueError(f"{name} must have {size} entries, got {value.size}")
    if not np.isfinite(value).all():
        raise ValueError(f"{name} is NaN or infinite: {value.tolist()}")
    return value


def target_geometry(settings, targets, position, velocity, orientation=None,
                    angular_velocity=None):
    """The `TargetGeometry` of the hand at `position` (and `orientation`, a unit quaternion,
    when the targets have orientations) under the operator's `velocity` (and
    `angular_velocity`, world frame), applied for `settings.cost_time_step`."""
    position = _finite_vector(position, "position")
    velocity = _finite_vector(velocity, "velocity")
    step = settings.cost_time_step
    distances = np.linalg.norm(targets.positions - position, axis=1)
    next_offsets = position + velocity * step - targets.positions
    if targets.orientations is None:
        return TargetGeometry(distances, next_offsets, None, None)
    if orientation is None:
        raise ValueError("the targets have orientations: the hand's orientation is needed")
    orientation = quaternion.unit_quaternions(orientation, "orientation").reshape(4)
    angular_velocity = _finite_vector(
        np.zeros(3) if angular_velocity is None else angular_velocity, "angular_velocity")
    conjugates = quaternion.conjugate(targets.orientations.T)
    angles = np.linalg.norm(quaternion.log_map(
        quaternion.multiply(orientation[:, np.newaxis], conjugates)), axis=0)
    turned = quaternion.multiply(quaternion.exp_map(angular_velocity * step), orientation)
    next_rotations = quaternion.log_map(quaternion.multiply(turned[:, np.newaxis], conjugates))
    return TargetGeometry(distances, next_offsets, angles, next_rotations.T)


def target_values(settings, geometry):
    """`(V_kappa now (N,), V_kappa after the operator's step (N,))`: each target's value at
    the hand's pose and at its next pose (`p'`, `q'`), translation plus weighted rotation."""
    translation = _translation(settings)
    now = huber_value(geometry.distances, *translation)
    after = huber_value(np.linalg.norm(geometry.next_offsets, axis=1), *translation)
    if geometry.angles is not None:
        rotation = _rotation(settings)
        weight = settings.rotation_weight
        now = now + weight * huber_value(geometry.angles, *rotation)
        after = after + weight * huber_value(np.linalg.norm(geometry.next_rotations, axis=1),
                                             *rotation)
    return now, after


def target_costs(settings, geometry):
    """`(Q_kappa (N,), V_kappa (N,))`: `Q = c(d) + V(d') [+ w (c(theta) + V(theta'))]`,
    `V = V(d) [+ w V(theta)]`."""
    step = settings.cost_time_step
    values, after = target_values(settings, geometry)
    q_values = huber_step_cost(geometry.distances, *_translation(settings), step) + after
    if geometry.angles is not None:
        q_values = q_values + settings.rotation_weight * huber_step_cost(
            geometry.angles, *_rotation(settings), step)
    return q_values, values


def goal_minimum(per_target, targets):
    """`(minimum (K,), target (K,))`: each goal's least value over its targets and the
    index of the target that has it (the first of equals), vectorised over targets."""
    per_target = np.asarray(per_target, dtype=float)
    if targets.goal_count == len(per_target) and (targets.goals == np.arange(
            targets.goal_count)).all():
        return per_target, np.arange(targets.goal_count)
    order = np.lexsort((per_target, targets.goals))
    first = np.searchsorted(targets.goals[order], np.arange(targets.goal_count))
    best = order[first]
    return per_target[best], best


class GoalCosts(typing.NamedTuple):
    """Per goal: `q_values` Q_g (K,), `values` V_g (K,), `best_targets` (K,) the target of
    least Q, and the `geometry` (per target) they came from."""

    q_values: np.ndarray
    values: np.ndarray
    best_targets: np.ndarray
    geometry: TargetGeometry


def goal_costs(settings, targets, position, velocity, orientation=None,
               angular_velocity=None):
    """Q_g, V_g and each goal's best target (`GoalCosts`) for the hand and the operator's
    command (see `target_geometry`)."""
    geometry = target_geometry(settings, targets, position, velocity, orientation,
                               angular_velocity)
    q_per_target, v_per_target = target_costs(settings, geometry)
    q_values, best = goal_minimum(q_per_target, targets)
    values, _ = goal_minimum(v_per_target, targets)
    return GoalCosts(q_values, values, best, geometry)


# ---------------------------------------------------------------------------------------------
# The posterior


def uniform_log_belief(goal_count):
    """The uniform prior, `log(1 / K)` for each of K goals."""
    return np.full(int(goal_count), -math.log(goal_count))


def log_normalised(log_belief):
    """`log_belief - logsumexp(log_belief)`: the log of probabilities that sum to 1."""
    log_belief = np.asarray(log_belief, dtype=float)
    largest = log_belief.max()
    return log_belief - (largest + math.log(np.exp(log_belief - largest).sum()))


def clip_log_belief(log_belief, max_probability):
    """`(log_belief, clipped)`: a normalised log belief with its largest probability set to
    `max_probability` when above it and the excess spread evenly over the other goals;
    `clipped` says whether it was above. One goal alone is never clipped."""
    log_belief = np.array(log_belief, dtype=float)
    count = len(log_belief)
    best = int(np.argmax(log_belief))
    if count == 1 or log_belief[best] <= math.log(max_probability):
        return log_belief, False
    excess = math.exp(log_belief[best]) - max_probability
    share = math.log(excess / (count - 1)) if excess > 0.0 else -math.inf
    log_belief = np.logaddexp(log_belief, share)
    log_belief[best] = math.log(max_probability)
    return log_belief, True


class PosteriorUpdate(typing.NamedTuple):
    """One update of the goal posterior: the new `log_belief` (K,), its `probabilities`
    (K,), whether the clip was active (`clipped`) and the `costs` it read."""

    log_belief: np.ndarray
    probabilities: np.ndarray
    clipped: bool
    costs: GoalCosts


def update_posterior(settings, targets, log_belief, position, velocity, orientation=None,
                     angular_velocity=None):
    """`log b_t = log b_{t-1} - (Q_g - V_g)`, normalised, then clipped at
    `settings.max_probability` (`PosteriorUpdate`). `velocity` (and `angular_velocity`) is
    the operator's command."""
    log_belief = np.asarray(log_belief, dtype=float)
    if log_belief.shape != (targets.goal_count,) or not np.isfinite(log_belief).all():
        raise ValueError(f"log_belief must be {targets.goal_count} finite numbers, got "
                         f"{log_belief!r}")
    costs = goal_costs(settings, targets, position, velocity, orientation, angular_velocity)
    updated = log_normalised(log_belief - (costs.q_values - costs.values))
    updated, clipped = clip_log_belief(updated, settings.max_probability)
    return PosteriorUpdate(updated, np.exp(updated), clipped, costs)


# ---------------------------------------------------------------------------------------------
# The assistance


def _unit_rows(vectors, lengths):
    safe = np.where(lengths > AT_TARGET, lengths, 1.0)
    return np.where((lengths > AT_TARGET)[:, np.newaxis], vectors / safe[:, np.newaxis], 0.0)


def goal_gradients(settings, costs):
    """`(translation (K, 3), rotation (K, 3) or None)`: each goal's gradient of its best
    target's value at the operator's next pose, faded on the distance and angle from that
    pose, not yet divided by lambda."""
    geometry, best = costs.geometry, costs.best_targets
    offsets = geometry.next_offsets[best]
    lengths = np.linalg.norm(offsets, axis=1)
    fade = np.minimum(1.0, lengths / settings.translation_fade_distance)
    translation = (huber_slope(lengths, *_translation(settings)) * fade)[:, np.newaxis] * \
        _unit_rows(offsets, lengths)
    if geometry.angles is None:
        return translation, None
    rotations = geometry.next_rotations[best]
    angles = np.linalg.norm(rotations, axis=1)
    fade = np.minimum(1.0, angles / settings.rotation_fade_angle)
    rotation = (settings.rotation_weight * huber_slope(angles, *_rotation(settings))
                * fade)[:, np.newaxis] * _unit_rows(rotations, angles)
    return translation, rotation


def assistance_action(settings, costs, weights):
    """`(linear (3,), angular (3,) or None)`: `-(1/lambda) (sum_g w_g grad Q_g) / sum w`,
    the assistance for goal weights `weights` (K,) (the belief for HOP); zeros when every
    weight is 0 (predict-then-assist passing the operator through)."""
    weights = np.asarray(weights, dtype=float)
    translation, rotation = goal_gradients(settings, costs)
    total = weights.sum()
    if not total > 0.0:
        return np.zeros(3), None if rotation is None else np.zeros(3)
    linear = -(weights @ translation) / (total * settings.translation_divisor)
    if rotation is None:
        return linear, None
    return linear, -(weights @ rotation) / (total * settings.rotation_divisor)


def blending_weights(probabilities, threshold):
    """Predict-then-assist's goal weights: one-hot on the most probable goal when it beats the
    second by more than `threshold`, else all 0 (the operator alone). With one goal its
    margin is its probability, 1."""
    probabilities = np.asarray(probabilities, dtype=float)
    weights = np.zeros(len(probabilities))
    best = int(np.argmax(probabilities))
    others = np.delete(probabilities, best)
    runner_up = others.max() if others.size else 0.0
    if probabilities[best] - runner_up > threshold:
        weights[best] = 1.0
    return weights


#: The goal weights `(settings, probabilities) -> (K,)` of each assistance by name
#: (`pbp_drake.core.methods.Method.assistance`): the belief itself or predict-then-assist's.
ASSISTANCE_WEIGHTS = {
    "hop": lambda settings, probabilities: np.asarray(probabilities, dtype=float),
    "predict_then_assist": lambda settings, probabilities: blending_weights(
        probabilities, settings.blending_threshold)}


def check_assistance(name):
    """Raises ValueError unless `name` is one of `ASSISTANCE_WEIGHTS`."""
    if name not in ASSISTANCE_WEIGHTS:
        raise ValueError(unknown_choice("method", name, ASSISTANCE_WEIGHTS))


class AssistedCommand(typing.NamedTuple):
    """The command of one tick: `velocity` (3,) and `angular_velocity` (3,) or None (the
    operator's plus the assistance), and `assisting` (the weights were not all 0)."""

    velocity: np.ndarray
    angular_velocity: typing.Optional[np.ndarray]
    assisting: bool


def assisted_command(method, settings, targets, probabilities, position, velocity,
                     orientation=None, angular_velocity=None):
    """The command `u + a` of `method` for the belief `probabilities` (K,) and the
    operator's command `u` = (`velocity`, `angular_velocity`) at the hand's pose; `u`
    alone when `settings.assistance` is False."""
    probabilities = np.asarray(probabilities, dtype=float)
    # Not negative: a log belief given for the belief would weigh every goal below 0, and
    # the assistance would stop without a word.
    if (probabilities.shape != (targets.goal_count,) or not np.isfinite(probabilities).all()
            or (probabilities < 0.0).any()):
        raise ValueError(f"goal_probabilities must be {targets.goal_count} finite numbers >= 0 "
                         f"(probabilities, not their logs), got {probabilities!r}")
    operator_angular = None if targets.orientations is None else (
        np.zeros(3) if angular_velocity is None
        else _finite_vector(angular_velocity, "angular_velocity"))
    operator_velocity = _finite_vector(velocity, "velocity")
    if not settings.assistance:
        # Not plus a zero action, which would turn a -0.0 into 0.0: bit for bit teleop's.
        return AssistedCommand(operator_velocity, operator_angular, False)
    check_assistance(method)
    weights = ASSISTANCE_WEIGHTS[method](settings, probabilities)
    costs = goal_costs(settings, targets, position, velocity, orientation, angular_velocity)
    linear, angular = assistance_action(settings, costs, weights)
    if angular is not None:
        angular = operator_angular + angular
    return AssistedCommand(operator_velocity + linear, angular, bool(weights.sum() > 0.0))
