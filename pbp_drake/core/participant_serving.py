"""When the virtual participant acts, in pure NumPy: one rule under every method, whose
name never reaches this module. Each tick it asks whether the robot serves its target,
lets go while it does and acts while it does not (`serving_step`): at once when the shown
intent names another object; after `serve_patience` of a hand that does not close in at
`serve_speed_fraction` of its own preferred speed (`robot_serves`), then for `hold_time` at
least. Which keys it presses is `pbp_drake.core.participant_reach`'s. The rule in full:
docs/tasks/reach.md, "The virtual participant"."""

import dataclasses

import numpy as np

# The shown intent's value where the method shows none (teleop; HOP with its assistance off).
NO_INTENT = -1


def preferred_speed(params, speed, distance):
    """The participant's own speed (m/s) at `distance` (m) from its target: `speed`, slowing
    in proportion within `slow_radius`, as when it drives (`participant_reach.drive_motion`)."""
    return speed * min(1.0, distance / params.slow_radius)


def robot_serves(params, speed, velocity, offset):
    """Whether a hand moving at `velocity` (2 or 3, m/s) closes in on a target `offset`
    (the same size, m) away at `serve_speed_fraction` of the participant's preferred speed
    there or more. At the target itself (offset ~ 0) anything serves."""
    offset = np.asarray(offset, float)
    distance = float(np.linalg.norm(offset))
    if distance < 1e-9:
        return True
    closing = float(np.asarray(velocity, float) @ offset) / distance
    return closing >= params.serve_speed_fraction * preferred_speed(params, speed, distance)


def keys_help(params, wanted, allowed):
    """Whether pressing `allowed`, what the keys allow of the velocity `wanted` (the forward
    key disabled), is worth it: at least `serve_speed_fraction` of it. Less (the way on
    lies ahead), no key helps, and it waits."""
    return not np.linalg.norm(allowed) < params.serve_speed_fraction * np.linalg.norm(wanted)


@dataclasses.dataclass(frozen=True)
class ServingMemory:
    """What the rule remembers between ticks: whether it acted, why (`took_over`: because
    the robot's motion did not serve, rather than its intent named another object), how
    many ticks it has watched the robot not serve, and how many more it keeps control."""

    acting: bool = False
    took_over: bool = False
    unserved_ticks: int = 0
    hold_ticks: int = 0

    def as_vector(self):
        return np.array([float(self.acting), float(self.took_over), float(self.unserved_ticks),
                         float(self.hold_ticks)])

    @classmethod
    def from_vector(cls, vector):
        acting, took_over, unserved, hold = vector
        return cls(acting > 0.5, took_over > 0.5, int(round(unserved)), int(round(hold)))


SERVING_MEMORY_SIZE = 4


def serving_step(params, speed, period, memory, shown_goal, target_index, offset, velocity,
                 own_motion):
    """One tick of the rule: `(act, memory)`.

    `shown_goal` is the object the robot shows it means (`NO_INTENT`: none shown);
    `target_index` the object the participant heads for, `offset` (2 or 3) from the hand to
    it; `velocity` the hand's velocity and `own_motion` the robot's own part of it, as the
    participant perceives them (`update_own_motion`)."""
    patience = int(round(params.serve_patience / period))
    shows = shown_goal != NO_INTENT
    if shows and shown_goal != target_index:
        return True, ServingMemory(acting=True)
    if memory.acting:
        if memory.hold_ticks > 0:
            return True, dataclasses.replace(memory, hold_ticks=memory.hold_ticks - 1)
        if shows or robot_serves(params, speed, own_motion, offset):
            return False, ServingMemory()
        return True, memory
    if robot_serves(params, speed, velocity, offset):
        return False, ServingMemory()
    unserved = memory.unserved_ticks + 1
    if unserved > patience:
        hold = int(round(params.hold_time / period))
        return True, ServingMemory(acting=True, took_over=True, hold_ticks=hold)
    return False, ServingMemory(unserved_ticks=unserved)


def update_own_motion(params, period, own_motion, velocity, sent_command):
    """The participant's sense of the robot's own motion after this tick: what the hand
    does (`velocity`) beyond what it asked of it (`sent_command`, the velocity it sent,
    zero while idle), averaged over `serve_patience`, so that the few ticks the hand takes
    to follow a new key press are not read as the robot pulling by itself."""
    weight = min(1.0, period / max(params.serve_patience, period))
    own_now = np.asarray(velocity, float) - np.asarray(sent_command, float)
    return (1.0 - weight) * np.asarray(own_motion, float) + weight * own_now


def robot_pulls(params, speed, own_motion):
    """Whether the robot is seen to move by itself at `serve_speed_fraction` of `speed` or
    more: then, going where the robot does not, the participant pushes against its pull
    (`VirtualOperator`'s compensation)."""
    return float(np.linalg.norm(own_motion)) >= params.serve_speed_fraction * speed
