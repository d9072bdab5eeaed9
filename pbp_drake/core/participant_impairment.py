"""Impairments of the virtual participant, in pure NumPy: a person who is noisy
(`next_motor_noise`), late (`delay_ticks`; the systems keep the queue) or mistaken
(`first_choice`). `ParticipantImpairment` is the scenario's `operator: !VirtualParticipant
{impairment: {...}}`; `PARTICIPANT_CONDITIONS` are the named levels that `pbp-drake study
--participant-condition` applies. The defaults change nothing. Everything random is drawn
from the run's seed, never from what the robot does, so one seed gives the same noise and
the same mistakes under every method (docs/results/impaired.md)."""

import dataclasses
import math

import numpy as np

# The random streams, each seeded with [seed, index, stream]: apart from each other and
# from the calibrated participant's own noise, seeded with [seed, tick]. The stream comes
# last and is not 0, as NumPy's SeedSequence ignores trailing zeros ([s, 1, 0] draws what
# [s, 1] draws).
MOTOR_NOISE_STREAM = 1
MOTOR_NOISE_START_STREAM = 2
MISTAKE_STREAM = 3
# A queue of commands longer than this (s) is no person's reaction.
LONGEST_COMMAND_DELAY = 10.0


@dataclasses.dataclass
class ParticipantImpairment:
    """How the virtual participant is impaired. The defaults: not at all."""

    #: Its motor noise (a fraction): a zero-mean Gaussian added to each axis of the velocity
    #: it commands while it acts, of standard deviation `command_noise` times its speed
    #: (m/s), and to each axis of its turn rate, times its `rotation_speed`; 0: none.
    command_noise: float = 0.0
    #: The motor noise's correlation time (s): it keeps its value about this long (an
    #: Ornstein-Uhlenbeck process); 0: a fresh draw every control tick.
    command_noise_time: float = 0.5
    #: Its commands reach the robot this long (s) after it decided them, rounded to whole
    #: control ticks, so it also reacts that much later; 0: at once.
    command_delay: float = 0.0
    #: The probability (0 to 1) that, each time it comes to know a target, it first heads
    #: for another object (each of the others as likely), drawn from the seed.
    mistake_probability: float = 0.0
    #: Heading for the wrong object, it sees its mistake this long (s) after it chose it,
    #: and turns to the true target.
    mistake_time: float = 1.0

    def problem(self):
        """What makes the impairment unusable, as `field: what is wrong`, or None."""
        for name in ("command_noise", "command_noise_time", "command_delay", "mistake_time"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                return f"{name} must be finite and not negative, got {value!r}"
        if not self.command_delay <= LONGEST_COMMAND_DELAY:
            return (f"command_delay {self.command_delay!r} s is longer than any person's "
                    f"reaction; expected at most {LONGEST_COMMAND_DELAY:g} s")
        if not 0.0 <= self.mistake_probability <= 1.0:
            return (f"mistake_probability must be a probability, 0 to 1, got "
                    f"{self.mistake_probability!r}")
        return None

    def validate(self):
        """Raises ValueError naming the first field that cannot be used."""
        problem = self.problem()
        if problem is not None:
            raise ValueError(problem)


#: The named conditions of `pbp-drake study --participant-condition`, each one impairment
#: alone at a level set once from what is known of people (docs/results/impaired.md says
#: where each comes from), never from how a method fares under it.
PARTICIPANT_CONDITIONS = {
    # Motor noise three times the calibrated participant's 10 % speed noise, held about
    # half a second: people correct their course intermittently, about twice a second.
    "noisy": ParticipantImpairment(command_noise=0.3, command_noise_time=0.5),
    # 0.3 s: the slow end of human visual reaction times (0.2 to 0.3 s), and a latency at
    # which teleoperation measurably degrades.
    "late": ParticipantImpairment(command_delay=0.3),
    # One target in five first mistaken for another (choice errors under time pressure),
    # corrected after a second (a look back at the scene and a choice reaction).
    "mistaken": ParticipantImpairment(mistake_probability=0.2, mistake_time=1.0),
}


def condition(name):
    """A copy of the named condition's impairment; ValueError for an unknown name."""
    if name not in PARTICIPANT_CONDITIONS:
        raise ValueError(f"participant condition {name!r} is unknown; use one of "
                         f"{', '.join(PARTICIPANT_CONDITIONS)}")
    return dataclasses.replace(PARTICIPANT_CONDITIONS[name])


def delay_ticks(delay, control_period):
    """`delay` (s) in whole control ticks (the nearest)."""
    return int(round(float(delay) / float(control_period)))


def is_noisy(impairment):
    return impairment.command_noise > 0.0


def initial_motor_noise(seed, scales):
    """The motor noise before the first tick: a draw from its stationary distribution (each
    axis N(0, scale^2)), so the run is as noisy from its start as later on."""
    scales = np.asarray(scales, float)
    rng = np.random.default_rng([int(seed), 0, MOTOR_NOISE_START_STREAM])
    return scales * rng.standard_normal(len(scales))


def next_motor_noise(impairment, control_period, seed, tick, previous, scales):
    """The motor noise (one value per axis) of control tick `tick`, from the previous
    tick's: `a previous + sqrt(1 - a^2) scales eps`, `a = exp(-period /
    command_noise_time)` (0 with no correlation time), `eps` standard normals drawn from
    `(seed, tick)`. Each axis stays N(0, scale^2)."""
    scales = np.asarray(scales, float)
    time_constant = impairment.command_noise_time
    keep = math.exp(-control_period / time_constant) if time_constant > 0 else 0.0
    fresh = math.sqrt(1.0 - keep * keep)
    rng = np.random.default_rng([int(seed), int(tick), MOTOR_NOISE_STREAM])
    return keep * np.asarray(previous, float) + fresh * scales * rng.standard_normal(
        len(scales))


def first_choice(impairment, seed, number, target, object_count):
    """The object it first heads for when `target` (an index of `object_count` objects)
    becomes the `number`-th target it knows in the run (0 the first): another object with
    `mistake_probability`, each of the others as likely, drawn from `(seed, number)`;
    otherwise `target`."""
    if impairment.mistake_probability <= 0.0 or object_count < 2:
        return int(target)
    rng = np.random.default_rng([int(seed), int(number), MISTAKE_STREAM])
    mistaken = rng.random() < impairment.mistake_probability
    other = int(rng.integers(object_count - 1))
    if not mistaken:
        return int(target)
    return other + 1 if other >= target else other
