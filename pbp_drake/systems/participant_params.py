"""The virtual participant's parameters: the scenario's `operator: !VirtualParticipant {...}`
fields (`pbp_drake.scenarios.schema.VirtualParticipant` adds none)."""

import dataclasses


@dataclasses.dataclass
class VirtualParticipantParams:
    """How the virtual participant behaves (see `VirtualParticipant`). `speed` (m/s) 0 takes
    the task's nominal speed, that of its DMPs. Its noise comes from the scenario's seed.

    The defaults are the reach task's calibration (issue 14): teleop only, on the tuning
    seeds, to the paper's users' teleop intervention ratio (0.92 to 0.95).
    """

    speed: float = 0.0
    rotation_speed: float = 0.8
    # It notices a new target this long (s) after it appears: seeing the ball move,
    # deciding and reaching for the keys. 0.5 s is the reach calibration (teleop then rests
    # about as long as the paper's users did); diagrams/hsr_obstacles.yaml keeps 0.3.
    reaction_delay: float = 0.5
    # Its direction is rotated by N(0, direction_noise) rad, its speed scaled by
    # (1 + N(0, speed_noise)).
    direction_noise: float = 0.1
    speed_noise: float = 0.1
    # Driving (teleop), it slows within this distance (m) of the target.
    slow_radius: float = 0.15
    # It counts as facing a point within this angle (rad).
    aligned_angle: float = 0.05
    # It turns at `rotation_speed` until the heading is this close (rad) to where it wants
    # it, then in proportion, so that it does not overshoot.
    turn_slowdown_angle: float = 0.3
    # Assisting, it takes the target and the object picked instead to stand in line when
    # their directions from the hand are closer than this (rad): no sidestep toward the
    # target separates them then, so it steps aside, at `aside_speed_fraction` of `speed`,
    # to the side that widens the angle between them.
    in_line_angle: float = 0.1
    aside_speed_fraction: float = 0.5
    # Assisting, once it has faced the target this long (s) and the estimate still names
    # another object, it goes to the target itself: it turns the target to its side and
    # sidesteps toward it (the forward key is disabled), until the estimate follows.
    insist_time: float = 1.0
    # Once it takes control among obstacles, it keeps it at least this long (s).
    hold_time: float = 0.5
