"""The order within one control tick, stated once for every system and every diagram
(why: docs/concepts/control-tick.md). Drake computes all discrete updates of one instant
from the values before it, so a tick has three stages:

1. **sense** at `t_k` (`SENSE_OFFSET`): the robot's state is sampled and the operator
   decides (a surrogate pilot's filter samples that decision at `pilot_offset`);
2. **decide** at `t_k + decide_offset(period)`: the DMP bank, the goal estimators, the
   heading, the task monitor and the moving obstacles update from the sense stage's values
   (none reads the task monitor: the operators read its `target` at the sense stage);
3. **report** (`report_offset`): what must see tick k's decisions, the hand-over and the
   task monitor's end at success.

Loggers publish before the updates of their instant, so tick k's decisions appear
`DECISION_LOG_SHIFT` samples later (`pbp_drake.builder.run.read_log`)."""

import math

SENSE_OFFSET = 0.0
DECIDE_FRACTION = 1e-6
DECISION_LOG_SHIFT = 1


def checked_period(control_period, name="control_period"):
    """`control_period` (s) as a float; ValueError, naming it `name`, unless it is finite
    and positive."""
    try:
        period = float(control_period)
    except (TypeError, ValueError):
        period = math.nan
    if not (math.isfinite(period) and period > 0.0):
        raise ValueError(f"{name} must be positive, got {control_period!r}")
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
