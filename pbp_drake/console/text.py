"""The console's words: what the page and the terminal say about a run, as pure functions
of numbers and scenarios (no Meshcat, no Drake)."""

import math

from pbp_drake.scenarios import (
    METHOD_NAMES, METHODS, Gamepad, GraspTask, counted, forward_key_enabled)


def method_name(method, alpha=None):
    """The method as a person reads it (`scenarios.METHOD_NAMES`): "pbp_alternated" is
    "PBP-Alt", ("fixed_alpha", 0.5) "Fixed alpha 0.50"; unknown names pass through."""
    name = METHOD_NAMES.get(method, method)
    if alpha is not None and method in METHODS and METHODS[method].takes_weight:
        name = f"{name} {alpha:.2f}"
    return name


def time_left(duration, now):
    """"time left 41 s": whole seconds until the time limit, rounded up (the last second
    shows as 1 s, not 0 s), never negative."""
    return f"time left {max(0, math.ceil(duration - now - 1e-9)):d} s"


def status_text(duration, now, switches=None, intervention_ratio=None):
    """The live status line of a run at simulated time `now` of `duration`: "time left
    41 s · 2 target switches · intervention 31 %". `switches` and `intervention_ratio`
    (0..1) are left out when None (a 2-D scene has no targets to switch)."""
    parts = [time_left(duration, now)]
    if switches is not None:
        parts.append(counted(switches, "target switch", "target switches"))
    if intervention_ratio is not None:
        parts.append(f"intervention {100.0 * intervention_ratio:.0f} %")
    return " · ".join(parts)


def result_text(success, task_time, stopped=False, why=None):
    """A task's outcome: "success in 14.2 s", "failed: time limit" (then `why`, from
    `failure_text`, when known), or, when the person ended the run, "stopped at 9.0 s"."""
    if success:
        return f"success in {task_time:.1f} s"
    if stopped:
        return f"stopped at {task_time:.1f} s"
    return "failed: time limit" + ("" if why is None else f"; {why}")


def failure_text(target, target_count, distance, success_distance=None, joints=(),
                 goal="object"):
    """Where a failed run ended: "the target was object 2 of 3, the hand 0.213 m from it
    (success within 0.050 m)"; `target` counts from 0 among `target_count` goals, each a
    `goal` (a grasping task of many grasps an object counts grasps), `success_distance`
    None leaves the bracket out; then the robot's `joints` that stand at a position limit,
    by name (the hand may be held there, short of the target)."""
    within = "" if success_distance is None else f" (success within {success_distance:.3f} m)"
    held = f"; at a joint limit: {', '.join(joints)}" if joints else ""
    return (f"the target was {goal} {target + 1} of {target_count}, the hand "
            f"{distance:.3f} m from it{within}{held}")


def controls_line(scenario):
    """What the person's keys or gamepad do in `scenario`'s task: six degrees of freedom in
    the grasping task, forward only where the method lets the person push forward
    (`forward_key_enabled`), up and down with the task's `z_range`."""
    grasping = isinstance(scenario.task, GraspTask)
    gamepad = isinstance(scenario.operator, Gamepad)
    limit = "" if forward_key_enabled(scenario) else " (not forward: the primitive drives it)"
    if gamepad and grasping:
        return (f"Gamepad: left stick moves the hand{limit}, triggers raise (RT) and lower "
                "(LT) it; right stick yaws and pitches, shoulders roll.")
    if gamepad:
        return f"Gamepad: left stick moves the hand{limit}, right stick turns it."
    if grasping:
        return (f"Keys: arrows move the hand{limit}, PageUp/PageDown raise and lower it; R "
                "switches to turning (arrows pitch and yaw, PageUp/PageDown roll).")
    up_down = ", R raises it and F lowers it" if scenario.vertical else ""
    return f"Keys: arrows move the hand{limit}, Q and E turn it{up_down}."


def progress_text(now, duration, realtime_factor):
    """The terminal's progress line: "t = 12.3 s of 60 s, 1.00x real time"."""
    return f"t = {now:.1f} s of {duration:g} s, {realtime_factor:.2f}x real time"
