"""The virtual participant's parameters: the scenario's `operator: !VirtualParticipant {...}`
fields, read by the reach participant (`pbp_drake.systems.operators.virtual_operator`); the
grasp participant (`pbp_drake.core.participant_grasp`) takes the defaults it shares."""

import dataclasses

from pbp_drake.core.participant_impairment import ParticipantImpairment


@dataclasses.dataclass
class VirtualParticipantParams:
    """How the virtual participant behaves (see the `VirtualOperator` system); its noise comes
    from the scenario's seed. The defaults are the reach task's calibration: teleop only, on
    the tuning seeds, to the paper's users' teleop intervention ratio (0.92 to 0.95)."""

    #: Its speed (m/s); 0 takes the task's nominal speed, that of its DMPs.
    speed: float = 0.0
    #: Its turn rate (rad/s).
    rotation_speed: float = 0.8
    #: It notices a new target this long (s) after it appears: seeing the ball move,
    #: deciding and reaching for the keys. 0.3 s is the reach calibration: with
    #: `serve_patience` after it, teleop then rests about as long as the paper's users did.
    reaction_delay: float = 0.3
    #: Its direction is rotated by N(0, direction_noise) rad.
    direction_noise: float = 0.1
    #: Its speed is scaled by (1 + N(0, speed_noise)) (a fraction).
    speed_noise: float = 0.1
    #: Driving (teleop), it slows within this distance (m) of the target.
    slow_radius: float = 0.15
    #: It counts as facing a point within this angle (rad).
    aligned_angle: float = 0.05
    #: It turns at `rotation_speed` until the heading is this close (rad) to where it wants
    #: it, then in proportion, so that it does not overshoot.
    turn_slowdown_angle: float = 0.3
    #: Assisting, the target and the object picked instead stand in line when their
    #: directions from the hand are closer than this (rad): it then steps aside, to the side
    #: that widens the angle between them.
    in_line_angle: float = 0.1
    #: The speed of its sidestep out of line, as a fraction of `speed`.
    aside_speed_fraction: float = 0.5
    #: Assisting, once it has faced the target this long (s) and the estimate still names
    #: another object, it turns the target to its side and sidesteps to it itself.
    insist_time: float = 1.0
    #: Assisting with a bounded wrist or keys that move the hand up and down, it moves the
    #: hand to where the tool can point at the target (`reposition_motion`) at most this
    #: long (s) for one target; still unable to, it goes to the target itself.
    reposition_time: float = 4.0
    #: Once it takes control (among obstacles, or because the robot's motion did not serve
    #: its target), it keeps it at least this long (s).
    hold_time: float = 0.5
    #: It lets the robot go while the hand closes in on its target at this fraction of its
    #: own preferred speed there or more (`pbp_drake.core.participant_serving`): the same
    #: rule under every method, set before any method ran, never tuned on one. With the
    #: forward key disabled it also waits when what the keys allow of the motion it wants
    #: is less than this fraction of it.
    serve_speed_fraction: float = 0.5
    #: It watches the robot this long (s) before it takes over from a robot that does not
    #: serve its target (about a simple reaction time, 0.24 s in the Model Human
    #: Processor), and its sense of the robot's own motion averages over as long.
    serve_patience: float = 0.25
    #: How it is impaired: motor noise, a delay of its commands, wrong first choices of
    #: target (`ParticipantImpairment`; the defaults: not at all).
    impairment: ParticipantImpairment = dataclasses.field(
        default_factory=ParticipantImpairment)

    # The fields below act among obstacles (the obstacle task, `VirtualOperator._avoid`);
    # `policy_compensation` in the reaching task too.

    #: Within this distance (m) of the target it no longer minds obstacles and goes straight
    #: on (in PBP only when the robot does not close in by itself, `min_closing_fraction`).
    final_approach_radius: float = 0.08
    #: Within this distance (m) of the target it pushes on through when no way round is left.
    push_through_radius: float = 0.3
    #: The times ahead (s) at which its local plan checks a motion: 1 to 100 positive times
    #: that increase; the last is the plan's horizon.
    plan_times: list[float] = dataclasses.field(
        default_factory=lambda: [0.1, 0.3, 0.6, 1.0, 1.5])
    #: How far ahead (s) it guesses where a moving obstacle will stop (on the line from the
    #: hand to the target); it picks the heading to arrive with from that guess.
    settle_time: float = 4.0
    #: How many directions (a count, 1 to 360) the plan tries, evenly spread round the
    #: circle from the one toward the target; each moving, turning either way, or not.
    plan_directions: int = 24
    #: The fastest it turns (rad/s) while planning among obstacles (`rotation_speed` if
    #: lower), and the turn rate its plan's turning score is measured against.
    max_turn_rate: float = 0.5
    #: The plan's weight (a factor) of turning toward the heading it wants (1 at
    #: `max_turn_rate` over the horizon) against progress to the target (1 at `speed`).
    turn_weight: float = 0.6
    #: The plan's weight (a factor) of keeping on with its last command (1 the same
    #: direction).
    keep_on_weight: float = 0.15
    #: Where the robot shows its intent, holding control it lets go once the robot's path
    #: (the straight line the shown path pulls back to) is clear of the obstacles by
    #: `release_factor` times its margin (a factor) and the robot faces within
    #: `release_heading_gap` (rad) of the heading it wants. It keeps control `hold_time` at
    #: least. Not holding it, it stays out while the robot faces within twice that gap and
    #: the robot's path and the hand's own keep its margin clear.
    release_factor: float = 1.5
    #: It lets go within this heading gap (rad).
    release_heading_gap: float = 0.05
    #: The heading it wants at the target is the nearest one whose footprint keeps
    #: `goal_margin_factor` times its margin (a factor) clear of where the obstacles stop.
    goal_margin_factor: float = 1.0
    #: Where it sees the robot pull by itself (`participant_serving.robot_pulls`: PBP-Cont's
    #: DMP), among obstacles and when it goes to the target itself in the reaching task it
    #: asks for the motion it wants minus the robot's own, at most this many times `speed`
    #: (a factor).
    policy_compensation: float = 3.0
    #: Its way round has stalled (`avoidance.update_watch`) once it has not come this much
    #: (m) closer to the target for `stall_time`.
    progress_step: float = 0.02
    #: Not `progress_step` closer for this long (s), it has stalled and pushes on through
    #: until it arrives (4 s: how long the moving cylinders take to settle).
    stall_time: float = 4.0
    #: In the last `final_approach_radius` (PBP) it leaves the robot alone only while the
    #: hand closes in on the target at this fraction of the nominal speed or more.
    min_closing_fraction: float = 0.25
