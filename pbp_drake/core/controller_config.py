"""What a shared-control controller is built from: `PbpControllerConfig`, plain dataclasses.

`make_pbp_controller(PbpControllerConfig(...), initial_ee_state, goals)` builds the
controller of any robot whose station takes an `ee_command` and gives an `ee_state` (the
HSR's, an arm's from `make_arm_station`, a user's own). A scenario is a `ControlSettings` and
its robot section a `HandLimits` with a nominal ``speed``, so a Python user and a YAML user
get the same controller (`pbp_drake.scenarios.resolve`'s `ResolvedScenario.controller`).
"""

import dataclasses
import typing

import numpy as np

from pbp_drake.core.coordinates import is_real
from pbp_drake.core.dmp import DmpBankModel, DmpSettings
from pbp_drake.core.dmp.primitive import Primitive, primitive_bank
from pbp_drake.core.goal_estimation import READS_POSE, GoalEstimatorSettings, estimator_entry
from pbp_drake.core.hand_over import check_limit
from pbp_drake.core.hindsight_optimization import HopSettings
from pbp_drake.core.methods import method_entry


@dataclasses.dataclass
class HandLimits:
    """The hand-over law's limits (`pbp_drake.core.hand_over`), which a scenario's robot
    section holds (`robot: !Hsr {max_hand_speed: ...}`)."""

    #: The fastest change of the commanded hand velocity (m/s^2; 1.0 is 0.03 m/s a tick at
    #: 30 Hz).
    max_hand_acceleration: float = 1.0
    #: The fastest commanded hand speed (m/s). 0.2 m/s is the HSR base's published limit:
    #: a hand driven faster for long runs its arm out of range.
    max_hand_speed: float = 0.2
    #: The same for the hand's heading (rad/s^2): the operator starting or stopping a turn.
    max_hand_yaw_acceleration: float = 4.0

    def validate(self):
        """Raises ValueError naming the first limit that is not finite and positive."""
        check_limit(self.max_hand_acceleration, "max_hand_acceleration", "m/s^2")
        check_limit(self.max_hand_speed, "max_hand_speed", "m/s")
        check_limit(self.max_hand_yaw_acceleration, "max_hand_yaw_acceleration", "rad/s^2")


@dataclasses.dataclass
class HandOverSettings(HandLimits):
    """`HandLimits` and how far the hand's heading may turn."""

    #: How far (rad) the heading may turn either way from where it starts; .inf: no bound
    #: (the HSR turns its base). An arm's wrist turns so far.
    max_heading_turn: float = float("inf")

    def validate(self):
        """Raises ValueError naming the first limit that cannot be used."""
        super().validate()
        if not (is_real(self.max_heading_turn) and self.max_heading_turn > 0):
            raise ValueError(f"max_heading_turn must be finite and positive (rad; .inf for "
                             f"no bound), got {self.max_heading_turn!r}")


@dataclasses.dataclass
class ControlSettings:
    """What the controller runs and how often: the fields a scenario file's `scenario:`
    shares with `PbpControllerConfig` (both are one)."""

    #: A method of the registry (`pbp_drake.core.methods.METHODS`): PBP alternated or
    #: continuous, PBP with no operator, explicit arbitration (fixed or confidence alpha),
    #: teleop, or the HOP baselines.
    method: str = "pbp_alternated"
    #: The arbitration weight of fixed_alpha, in [0, 1].
    alpha: float = 0.5
    #: The control tick's period (s): the controller decides once a tick.
    control_period: float = 0.01
    #: The DMPs' gains and basis.
    dmp: DmpSettings = dataclasses.field(default_factory=DmpSettings)
    #: The DMPs' duration tau (s); 0: from the demonstration (2-D scenes) or the farthest
    #: goal's distance over the nominal speed (the robot's `speed`).
    dmp_duration: float = 0.0
    #: How the followed goal is estimated.
    goal_estimator: GoalEstimatorSettings = dataclasses.field(
        default_factory=GoalEstimatorSettings)
    #: HOP's cost model, posterior and assistance (hop, predict_then_assist and the
    #: maxent_command estimator).
    hop: HopSettings = dataclasses.field(default_factory=HopSettings)

    def control_settings(self):
        """Its `ControlSettings` fields, by name."""
        return {field.name: getattr(self, field.name)
                for field in dataclasses.fields(ControlSettings)}

    def validate_settings(self):
        """Raises ValueError naming the first of its numbers or settings that cannot be
        used (its method is checked by its user, who knows the methods it runs)."""
        if not (is_real(self.alpha) and np.isfinite(self.alpha) and 0.0 <= self.alpha <= 1.0):
            raise ValueError(f"alpha must lie in [0, 1], got {self.alpha!r}")
        check_limit(self.control_period, "control_period", "s")
        if not (is_real(self.dmp_duration) and np.isfinite(self.dmp_duration)
                and self.dmp_duration >= 0.0):
            raise ValueError(f"dmp_duration must be finite and not negative (0: derived), "
                             f"got {self.dmp_duration!r}")
        kinds = {"dmp": DmpSettings, "goal_estimator": GoalEstimatorSettings, "hop": HopSettings}
        for name, kind in kinds.items():
            if not isinstance(getattr(self, name), kind):
                raise ValueError(f"{name} must be {kind.__name__}, got "
                                 f"{type(getattr(self, name)).__name__}")
            try:
                getattr(self, name).validate()
            except ValueError as error:
                raise ValueError(f"{name}: {error}") from None


@dataclasses.dataclass
class PbpControllerConfig(ControlSettings):
    """Everything `make_pbp_controller` builds from; one default per knob, the scenario
    file's."""

    #: The DMPs' nominal speed (m/s), for their duration when dmp_duration is 0
    #: (`nominal_duration`).
    nominal_speed: float = 0.12
    #: The hand-over law's limits, which every method's command goes through.
    hand_over: HandOverSettings = dataclasses.field(default_factory=HandOverSettings)
    #: A taught primitive (`pbp_drake.core.dmp.primitive`) whose shape every goal's DMP
    #: takes; None: straight paths. A scenario's resolution reads it from `dmp.primitive`.
    dmp_primitive: typing.Optional[Primitive] = None

    def validate(self):
        """Raises ValueError naming the first field that cannot be used."""
        method_entry(self.method)
        self.validate_settings()
        check_limit(self.nominal_speed, "nominal_speed", "m/s")
        if not isinstance(self.hand_over, HandOverSettings):
            raise ValueError(f"hand_over must be HandOverSettings, got "
                             f"{type(self.hand_over).__name__}")
        try:
            self.hand_over.validate()
        except ValueError as error:
            raise ValueError(f"hand_over.{error}") from None
        if estimator_entry(self.goal_estimator.method).reads == READS_POSE:
            raise ValueError(f"goal_estimator.method {self.goal_estimator.method} reads grasp "
                             f"orientations, which a position controller has not")

    @property
    def blend_mode(self):
        """The blender's mode (`Method.blend_mode`); None for the HOP baselines, which have
        no blender."""
        return method_entry(self.method).blend_mode

    def duration_for(self, start, goals):
        """The DMPs' duration (s) from `start` (3,) to `goals` (K, 3): `dmp_duration`, or
        when 0 `nominal_duration`'s at `nominal_speed`."""
        primitive = self.dmp_primitive
        return self.dmp_duration or nominal_duration(
            start, goals, self.nominal_speed, self.goal_estimator.group_mass > 0.0,
            primitive.length_ratio if primitive else 1.0)

    def dmp_bank(self, start, goals):
        """The DMP bank from `start` (3,) to each of `goals` (K, 3): straight paths, or the
        taught primitive's shape, of `duration_for(start, goals)`."""
        start, goals = np.asarray(start, float), np.asarray(goals, float)
        duration = self.duration_for(start, goals)
        if self.dmp_primitive is not None:
            return primitive_bank(self.dmp_primitive, start, len(goals), duration)
        return DmpBankModel.straight(start, len(goals), duration, self.dmp)


def nominal_duration(start, goals, speed, grouped, length_ratio=1.0):
    """The DMPs' duration (s) when none is given: the farthest goal's distance from `start`
    over `speed` (all DMPs share one phase, so the farthest goal is reached at the nominal
    speed and the nearer ones slower); with goal groups (`grouped`), the median goal's (why:
    docs/concepts/goal-estimators.md, "Many goals: goal groups"); times `length_ratio`, a
    taught primitive's path length over its chord."""
    distances = np.linalg.norm(np.asarray(goals, float) - np.asarray(start, float), axis=1)
    return float(np.median(distances) if grouped else np.max(distances)) / speed * length_ratio
