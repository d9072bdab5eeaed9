"""The order within one control tick, stated once for every system and every diagram.

Drake computes all discrete updates of one instant from the values before that instant, so
two systems that update at the same tick cannot see each other's new state. A PBP tick has
three stages, in this order:

1. **sense** at `t_k` (offset `SENSE_OFFSET`): the robot's state is sampled (`SampleHold`)
   and the operator decides (it reads the robot's state and Meshcat's input).
   A surrogate pilot's corruption of the operator's decision (`pilot_filters`) samples
   that decision half-way to the decide stage (`pilot_offset`): the robot reads the
   corrupted decision of the same tick, not one a tick late.
2. **decide** at `t_k + decide_offset(period)`: the DMP bank, the goal estimator, the heading,
   the task monitor and the moving obstacles update from the state sampled at `t_k` and the
   operator's decision of the same tick (as the paper's Alg. 2 reads them). The blender's
   output depends on its inputs only, so the command the robot follows from `t_k` on is
   the one of tick k.
3. **report**, a millionth of a period after a decide-stage update (`report_offset`):
   publish events that must see the decisions of tick k, such as the task monitor ending
   the simulation at success, and the hand-over (`HandOver`), whose state is the command
   the robot follows: it reads the blender's reference of tick k there, and no plant step
   lies between the tick and its report stage. A publish at the decide instant itself would run
   before that instant's updates (Drake publishes at the end of the step that reaches an instant and
   updates at the start of the next one).

The decide stage sits a millionth of the control period after the tick: long before any
plant step that follows the tick, and far from the next tick. Systems of the decide stage
use it by default, so neither a diagram nor user code states an offset.

The task monitor updates at the decide stage too, so no other decide-stage system reads
its outputs (they would see the last tick's): the operators read its `target` at the sense
stage.

Loggers publish before the updates of their instant: a log sample at `t_k` holds the plant's
state at `t_k` but the decisions of tick k - 1. `DECISION_LOG_SHIFT` is how many samples
later the decisions of tick k appear (see `pbp_drake.builder.run.read_log`).
"""

import math

SENSE_OFFSET = 0.0
DECIDE_FRACTION = 1e-6
DECISION_LOG_SHIFT = 1


def checked_period(control_period):
    """`control_period` (s) as a float; ValueError unless it is finite and positive."""
    period = float(control_period)
    if not (math.isfinite(period) and period > 0.0):
        raise ValueError(f"control_period must be positive, got {control_period!r}")
    return period


def checked_update_offset(update_offset, control_period):
    """`update_offset` (s; None: the decide stage); ValueError unless in [0, control_period)."""
    if update_offset is None:
        return decide_offset(control_period)
    if not (math.isfinite(update_offset) and 0.0 <= update_offset < control_period):
        raise ValueError(f"update_offset must be in [0, control_period), got {update_offset!r}")
    return update_offset


def decide_offset(control_period):
    """The offset (s) after each tick at which the decide stage updates."""
    return float(control_period) * DECIDE_FRACTION


def pilot_offset(control_period):
    """The offset (s) after each tick at which a pilot's filter samples the operator's
    decision of the tick: after the sense stage, before the decide stage."""
    return 0.5 * decide_offset(control_period)


def report_offset(control_period, update_offset=None):
    """The offset (s) after each tick at which a publish sees the decisions of an update at
    `update_offset` (the decide stage when None)."""
    if update_offset is None:
        update_offset = decide_offset(control_period)
    return float(update_offset) + decide_offset(control_period)
