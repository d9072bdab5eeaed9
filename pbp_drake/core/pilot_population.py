"""A population of virtual participants, one drawn for each trial from its seed, in pure
NumPy: after Backman, Kulić and Chung (2023), whose simulated users are sampled over four
parameters, conformance to the assistant, proficiency, aggressiveness and speed. Each trial
draws one level in [0, 1) per parameter (`population_levels`), and each field takes the
point of its range at its parameter's level (`LEVEL_RAISES`). The maps and ranges are ours,
each spanning the calibrated participant's value (docs/concepts/pilots.md says why)."""

import dataclasses

import numpy as np

from pbp_drake.core.participant_params import VirtualParticipantParams
from pbp_drake.core.surrogate_pilots import POPULATION_STREAM

#: Backman et al.'s four parameters, in the order they are drawn.
POPULATION_PARAMETERS = ("conformance", "proficiency", "aggressiveness", "speed")
#: Each drawn field: (its parameter, whether a higher level raises it).
LEVEL_RAISES = {
    "serve_patience": ("conformance", True),
    "serve_speed_fraction": ("conformance", False),
    "direction_noise": ("proficiency", False),
    "speed_noise": ("proficiency", False),
    "reaction_delay": ("proficiency", False),
    "insist_time": ("aggressiveness", False),
    "rotation_speed": ("aggressiveness", True),
    "speed_factor": ("speed", True),
}


@dataclasses.dataclass
class ParticipantPopulationParams:
    """Each trial's participant drawn from the trial's seed: `participant`'s fields, but
    those below, each drawn in its range `[low, high]` (`drawn_values`)."""

    #: The participant the draws start from (its other fields are kept).
    participant: VirtualParticipantParams = dataclasses.field(
        default_factory=VirtualParticipantParams)
    #: Conformance: how long (s) it watches a robot that does not serve its target before
    #: it takes over.
    serve_patience: list[float] = dataclasses.field(default_factory=lambda: [0.15, 0.6])
    #: Conformance: the share of its own preferred speed the robot must close in at.
    serve_speed_fraction: list[float] = dataclasses.field(default_factory=lambda: [0.3, 0.7])
    #: Proficiency: its direction noise (rad).
    direction_noise: list[float] = dataclasses.field(default_factory=lambda: [0.05, 0.2])
    #: Proficiency: its speed noise (a fraction).
    speed_noise: list[float] = dataclasses.field(default_factory=lambda: [0.05, 0.2])
    #: Proficiency: how long (s) it takes to notice a new target.
    reaction_delay: list[float] = dataclasses.field(default_factory=lambda: [0.2, 0.6])
    #: Aggressiveness: how long (s) it faces the target before it goes there itself.
    insist_time: list[float] = dataclasses.field(default_factory=lambda: [0.5, 2.0])
    #: Aggressiveness: its turn rate (rad/s).
    rotation_speed: list[float] = dataclasses.field(default_factory=lambda: [0.5, 1.1])
    #: Speed: a factor on the operator's speed.
    speed_factor: list[float] = dataclasses.field(default_factory=lambda: [0.75, 1.25])


def population_levels(seed):
    """`{parameter: level in [0, 1)}` of the trial with `seed` (POPULATION_PARAMETERS)."""
    uniforms = np.random.default_rng([int(seed), POPULATION_STREAM]).random(
        len(POPULATION_PARAMETERS))
    return dict(zip(POPULATION_PARAMETERS, (float(u) for u in uniforms)))


def drawn_values(population, seed):
    """`{field: value}` of the trial with `seed`: each field of `LEVEL_RAISES` at its
    parameter's level in its range."""
    levels = population_levels(seed)
    values = {}
    for name, (parameter, raises) in LEVEL_RAISES.items():
        low, high = (float(bound) for bound in getattr(population, name))
        level = levels[parameter] if raises else 1.0 - levels[parameter]
        values[name] = low + level * (high - low)
    return values


def drawn_participant(population, seed, operator_speed):
    """The participant of the trial with `seed`: `population.participant` with the drawn
    fields, its `speed` the drawn `speed_factor` times `operator_speed` (m/s, the speed the
    participant would move at undrawn)."""
    values = drawn_values(population, seed)
    factor = values.pop("speed_factor")
    return dataclasses.replace(population.participant, speed=factor * float(operator_speed),
                               **values)


def population_problem(population):
    """The first field of `population` that cannot be used, as `name: why`, or None: each
    range two finite numbers, low <= high, not negative (rates and factors positive)."""
    for name in LEVEL_RAISES:
        bounds = getattr(population, name)
        if len(bounds) != 2:
            return f"{name} {bounds} needs two numbers; expected [low, high]"
        low, high = (float(bound) for bound in bounds)
        if not (np.isfinite(low) and np.isfinite(high)):
            return f"{name} {bounds} must be two finite numbers [low, high]"
        if low > high:
            return f"{name} {bounds} is reversed; expected [low, high] with low <= high"
        positive = name in ("rotation_speed", "speed_factor")
        if low < 0 or (positive and low <= 0):
            return (f"{name} {bounds} must be {'positive' if positive else 'not negative'}")
    return None
