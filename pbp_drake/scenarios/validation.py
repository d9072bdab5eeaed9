"""The checks of a scenario's numbers, before anything is computed from them: every number
finite and of a sane size (`check_numbers`), time steps, the seed, the tasks' ranges and
counts, the operators' fields. Each raises a ScenarioError as `field.path: what is wrong,
what is expected`.
"""

import dataclasses
import math
import numbers

import numpy as np
from pydrake.systems.analysis import GetIntegrationSchemes

from pbp_drake.core.choices import unknown_choice
from pbp_drake.core.coordinates import is_real
from pbp_drake.core.pilot_population import ParticipantPopulationParams, population_problem
from pbp_drake.core.surrogate_pilots import ProportionalPilotParams
from pbp_drake.scenarios.bounds import MAX_GOALS
from pbp_drake.scenarios.schema import ScenarioError


# No length, time, gain or speed of a scenario comes near this; beyond it a norm or a
# square overflows (1e300 squared is inf) and numpy answers with warnings and NaN.
LARGEST_NUMBER = 1e12
# The shortest time step (s) a scenario may ask for: a simulated second then takes a
# million steps; a smaller one (1e-300 passes every "positive" check) never ends.
SHORTEST_TIME_STEP = 1e-6
# The longest a DMP may last (s); a far goal over a tiny robot.speed would otherwise give
# a duration whose square overflows in the DMP's gains.
LONGEST_DMP_DURATION = 1e6
# The most grasps an object of the grasping task may offer: 100 objects of 1,000 grasps are
# MAX_GOALS goals.
MAX_GRASPS_PER_OBJECT = 1000
# The most likely goals' paths a page draws (`scenario.likely_paths`): a few are what a
# person can follow.
MAX_LIKELY_PATHS = 20
# Fields where `.inf` is a documented value ("no limit"), by their path's last name.
INFINITY_MEANS_NO_LIMIT = ("base_acceleration_limits", "arm_acceleration_limits")


def check_numbers(config, field="scenario"):
    """Every number in `config` (dataclasses, Drake's config structs and lists, nested) is
    finite and at most LARGEST_NUMBER in size; `.inf` only where it means no limit."""
    if isinstance(config, bool) or config is None or isinstance(config, str):
        return
    if isinstance(config, numbers.Real):
        _check_number(config, field)
    elif isinstance(config, (list, tuple)):
        for index, item in enumerate(config):
            check_numbers(item, f"{field}[{index}]")
    elif dataclasses.is_dataclass(config):
        for member in dataclasses.fields(config):
            check_numbers(getattr(config, member.name), f"{field}.{member.name}")
    elif getattr(type(config), "__fields__", None) is not None:
        for member in type(config).__fields__:
            check_numbers(getattr(config, member.name), f"{field}.{member.name}")


def _check_number(value, field):
    if isinstance(value, numbers.Integral):
        # Integers: the seed may be any size numpy takes; counts are bounded where used.
        return
    if math.isnan(value):
        raise ScenarioError(f"{field}: NaN is not a number here; expected a finite number")
    if math.isinf(value):
        if value > 0 and field.split(".")[-1].split("[")[0] in INFINITY_MEANS_NO_LIMIT:
            return
        raise ScenarioError(f"{field}: {value} is infinite; expected a finite number")
    if abs(value) > LARGEST_NUMBER:
        raise ScenarioError(f"{field}: {value:g} is too large; expected a number of size at "
                            f"most {LARGEST_NUMBER:g}")


def require_finite(config, field, names, positive=True):
    """Each of `names` of `config` (0 where it has no such field) is finite and positive,
    or with `positive=False` finite and not negative; the error names `field.name`."""
    least = "positive" if positive else "not negative"
    for name in names:
        value = getattr(config, name, 0.0)
        if not (is_real(value) and math.isfinite(value)
                and (value > 0 if positive else value >= 0)):
            shown = value if is_real(value) else repr(value)  # a string '3' said as one
            raise ScenarioError(f"{field}.{name} must be finite and {least}, got {shown}")


def check_time_steps(time_steps):
    """`time_steps`: (field, value) pairs, each at least SHORTEST_TIME_STEP."""
    for field, value in time_steps:
        if not value >= SHORTEST_TIME_STEP:
            raise ScenarioError(f"{field} {value:g} s is too short; expected at least "
                                f"{SHORTEST_TIME_STEP:g} s")


def check_duration(duration, control_period):
    """The time limit holds at least one control tick: a run lasts the whole ticks nearest
    to it, and a shorter one would end before the controller ever decided."""
    if not duration >= control_period:
        raise ScenarioError(f"scenario.duration {duration:g} s is shorter than one control "
                            f"tick (scenario.control_period {control_period:g} s); expected at "
                            f"least {control_period:g} s")


def check_simulator(config, field="scenario.simulator"):
    """Drake's `SimulatorConfig` of a scenario: an integration scheme Drake has, a positive
    step size and accuracy, a real-time rate not negative (Drake takes a negative one as
    0, as fast as possible), and a start at 0 s, which every time of a scenario counts
    from (its ticks, an operator's script)."""
    schemes = GetIntegrationSchemes()
    if config.integration_scheme not in schemes:
        raise ScenarioError(unknown_choice(f"{field}.integration_scheme",
                                           config.integration_scheme, schemes))
    require_finite(config, field, ("max_step_size", "accuracy"))
    require_finite(config, field, ("target_realtime_rate",), positive=False)
    if config.start_time != 0.0:
        raise ScenarioError(f"{field}.start_time {config.start_time:g} s: a scenario's times "
                            "(its control ticks, its duration, an operator's script) count "
                            "from 0; expected 0")


def check_seed(seed, field="scenario.seed"):
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
        raise ScenarioError(f"{field} {seed!r} cannot seed the random draws; expected a "
                            "non-negative integer")


def check_range(config, field, name, within=None):
    """`config.name` is `[low, high]` with low <= high (and inside `within`)."""
    low_high = getattr(config, name)
    if len(low_high) != 2:
        raise ScenarioError(f"{field}.{name} {low_high} needs two numbers; expected "
                            "[low, high]")
    low, high = low_high
    if low > high:
        raise ScenarioError(f"{field}.{name} {low_high} is reversed; expected [low, high] "
                            "with low <= high")
    if within is not None and not within[0] <= low <= high <= within[1]:
        raise ScenarioError(f"{field}.{name} {low_high} leaves [{within[0]}, {within[1]}]; "
                            f"expected [low, high] inside it")


def check_count(value, field, least, most, hint=""):
    if not least <= value <= most:
        raise ScenarioError(f"{field} {value} is out of range; expected {least} to "
                            f"{most}{hint}")


def check_dmp_duration(duration, control_period, field):
    """The DMPs last at least one control tick (a shorter one is over before it is
    stepped, and its gains, 1 / duration squared, blow up) and at most
    LONGEST_DMP_DURATION."""
    if not control_period <= duration <= LONGEST_DMP_DURATION:
        raise ScenarioError(f"{field} gives the DMPs a duration of {duration:g} s; expected "
                            f"{control_period:g} s (scenario.control_period) to "
                            f"{LONGEST_DMP_DURATION:g} s")


def check_reach_task(task):
    require_finite(task, "scenario.task", ("success_distance", "min_separation"))
    for name in ("x_range", "y_range"):
        check_range(task, "scenario.task", name)
    if task.z_range:
        check_range(task, "scenario.task", "z_range")
    check_object_count(task)
    check_switch_schedule(task)
    if task.grid_objects:
        if task.objects:
            raise ScenarioError("scenario.task.grid_objects places objects on a grid; "
                                "scenario.task.objects are given: remove one")
        switches = len(task.switch_schedule) > 1
        check_count(task.grid_objects, "scenario.task.grid_objects", 2 if switches else 1,
                    MAX_GOALS, " (a target switch needs 2 objects)" if switches else "")


def check_object_count(task):
    """The range [low, high] of how many objects a task draws, each 1 to 100: objects are
    placed min_separation apart in front of the robot, and a few dozen fit."""
    check_range(task, "scenario.task", "object_count")
    for index in (0, 1):
        check_count(task.object_count[index], f"scenario.task.object_count[{index}]", 1, 100)


def check_switch_schedule(task):
    """The progress thresholds of the target switches: 0.0 first, increasing, below 1."""
    schedule = np.asarray(task.switch_schedule, float)
    if (len(schedule) == 0 or schedule[0] != 0.0 or np.any(np.diff(schedule) <= 0)
            or schedule[-1] >= 1.0):
        raise ScenarioError(f"scenario.task.switch_schedule {task.switch_schedule} must "
                            "start at 0.0 and increase strictly below 1.0")


def check_grasp_task(task):
    """The grasping task's (`GraspTask`) sizes, ranges, counts and success region."""
    field = "scenario.task"
    require_finite(task, field, ("min_separation", "height", "table_height", "object_radius",
                                 "object_height", "success_distance", "success_angle"))
    require_finite(task, field, ("grasp_depth",), positive=False)
    for name in ("x_range", "y_range"):
        check_range(task, field, name)
    check_object_count(task)
    check_count(task.grasps_per_object, f"{field}.grasps_per_object", 1, MAX_GRASPS_PER_OBJECT)
    # Beyond a quarter turn a side grasp approaches from behind the object, toward the
    # robot, which the HSR's arm cannot do.
    check_range(task, field, "approach_yaw_range", within=(-90.0, 90.0))
    check_range(task, field, "roll_range", within=(-180.0, 180.0))
    if not task.success_angle < 180.0:
        raise ScenarioError(f"{field}.success_angle {task.success_angle} degrees admits "
                            "every orientation; expected an angle below 180")
    if not 0.0 <= task.top_probability <= 1.0:
        raise ScenarioError(f"{field}.top_probability {task.top_probability} is no "
                            "probability; expected a number in [0, 1]")
    size = task.table_size
    if len(size) != 2 or not all(np.isfinite(side) and side > 0 for side in size):
        raise ScenarioError(f"{field}.table_size {size} needs two positive lengths (m); "
                            "expected [x, y]")
    check_switch_schedule(task)


def check_obstacle_task(task):
    require_finite(task, "scenario.task",
                   ("success_distance", "obstacle_radius", "obstacle_height",
                    "obstacle_spacing"))
    require_finite(task, "scenario.task", ("obstacle_speed",), positive=False)
    # Obstacles start 0.45 m from each other, the robot and the target: a few dozen fit.
    # Without any, the station has no obstacle input for the task to drive.
    check_count(task.obstacle_count, "scenario.task.obstacle_count", 1, 100,
                " (a task without obstacles is the reaching task: an untagged task)")
    for name in ("x_range", "y_range", "obstacle_x_range", "obstacle_y_range"):
        check_range(task, "scenario.task", name)
    if task.obstacle_starts:
        if len(task.obstacle_starts) != task.obstacle_count:
            raise ScenarioError(f"scenario.task.obstacle_starts holds "
                                f"{len(task.obstacle_starts)} starts; obstacle_count is "
                                f"{task.obstacle_count}: give each obstacle one start")
        for index, start in enumerate(task.obstacle_starts):
            if len(start) != 2 or not all(math.isfinite(value) for value in start):
                raise ScenarioError(f"scenario.task.obstacle_starts[{index}] {start} is no "
                                    "floor position; expected two finite numbers (x, y)")
            # As a drawn obstacle: none starts on the robot, in collision from the start.
            if math.hypot(*start) < task.obstacle_spacing:
                raise ScenarioError(
                    f"scenario.task.obstacle_starts[{index}] {start} stands "
                    f"{math.hypot(*start):.2f} m from the robot's base at (0, 0); expected "
                    f"at least obstacle_spacing {task.obstacle_spacing:g} m from it")
    check_range(task, "scenario.task", "activation_range", within=(0.0, 1.0))


def check_bent_path(path):
    """A `BentPath` is 2-D, goes somewhere, and has a sensible number of samples."""
    field = "scenario.demonstration"
    if len(path.start) != 2 or len(path.goal) != 2:
        raise ScenarioError(f"{field}.start {path.start} and goal {path.goal}: a bent path "
                            "is 2-D; expected two numbers each")
    if math.hypot(path.goal[0] - path.start[0], path.goal[1] - path.start[1]) < 1e-6:
        raise ScenarioError(f"{field}.goal {path.goal} is where start is; expected a goal "
                            "at least 1e-6 away")
    require_finite(path, field, ("duration",))
    check_time_steps([(f"{field}.duration", path.duration)])
    check_count(path.sample_count, f"{field}.sample_count", 3, 100_000)


def check_direction(axis, dimension, field):
    """`axis` is a vector of `dimension` long enough to be normalized (1e-300 passes a
    nonzero test, but its norm underflows to 0)."""
    if len(axis) != dimension or not math.hypot(*axis) >= 1e-6:
        raise ScenarioError(f"{field} {axis} is no direction; expected a vector of "
                            f"dimension {dimension} and length at least 1e-6")


# The virtual participant's plan scores 3 (directions + 1) motions at each of its times,
# every tick: a direction a degree is already far finer than the plan needs.
MOST_PLAN_DIRECTIONS = 360
MOST_PLAN_TIMES = 100


def check_virtual_participant(operator, field="scenario.operator"):
    """The reaching and obstacle fields of `operator: !VirtualParticipant`
    (`VirtualParticipantParams`): what it divides by, times, rates and steps positive, its
    other numbers not negative, `plan_directions` a count, `plan_times` increasing, and its
    `impairment` (`ParticipantImpairment.problem`)."""
    problem = operator.impairment.problem()
    if problem is not None:
        raise ScenarioError(f"{field}.impairment.{problem}")
    require_finite(operator, field, (
        "slow_radius", "turn_slowdown_angle", "settle_time", "max_turn_rate",
        "release_heading_gap", "policy_compensation", "progress_step", "stall_time"))
    require_finite(operator, field, (
        "final_approach_radius", "push_through_radius", "turn_weight", "keep_on_weight",
        "release_factor", "goal_margin_factor", "min_closing_fraction", "aligned_angle",
        "in_line_angle", "aside_speed_fraction", "insist_time", "reposition_time",
        "serve_speed_fraction", "serve_patience", "hold_time"),
        positive=False)
    directions = operator.plan_directions
    if isinstance(directions, bool) or not isinstance(directions, numbers.Integral):
        raise ScenarioError(f"{field}.plan_directions {directions!r} is no count; expected "
                            f"a whole number, 1 to {MOST_PLAN_DIRECTIONS}")
    check_count(directions, f"{field}.plan_directions", 1, MOST_PLAN_DIRECTIONS)
    times = np.asarray(operator.plan_times, float)
    if (times.ndim != 1 or not 1 <= len(times) <= MOST_PLAN_TIMES
            or not np.all(np.isfinite(times)) or times[0] <= 0
            or np.any(np.diff(times) <= 0)):
        raise ScenarioError(f"{field}.plan_times {operator.plan_times} must be 1 to "
                            f"{MOST_PLAN_TIMES} positive times (s) that increase strictly, "
                            "e.g. [0.1, 0.3, 0.6, 1.0, 1.5]")


def check_pilot(operator, field="scenario.operator"):
    """A surrogate pilot's fields (`pbp_drake.scenarios.pilots`): eps and p probabilities in
    [0, 1]; the proportional pilot's gain positive and max_speed not negative (0: the
    task's operator speed); the population's ranges `[low, high]` finite, low <= high;
    and the base participant's fields (`check_virtual_participant`)."""
    for name in ("eps", "p"):
        value = getattr(operator, name, None)
        if value is not None and not (np.isfinite(value) and 0.0 <= value <= 1.0):
            raise ScenarioError(f"{field}.{name} {value} is no probability; expected a number "
                                "in [0, 1]")
    if isinstance(operator, ProportionalPilotParams):
        require_finite(operator, field, ("gain",))
        require_finite(operator, field, ("max_speed", "dead_zone"), positive=False)
    if isinstance(operator, ParticipantPopulationParams):
        problem = population_problem(operator)
        if problem is not None:
            raise ScenarioError(f"{field}.{problem}")
    participant = getattr(operator, "participant", None)
    if participant is not None:
        require_finite(participant, f"{field}.participant",
                       ("speed", "rotation_speed", "reaction_delay", "direction_noise",
                        "speed_noise"), positive=False)
        check_virtual_participant(participant, f"{field}.participant")


#: A period within this fraction of a whole multiple of its time step runs at that
#: multiple: the paper's 30 Hz, 0.0333 s, is 10 plant steps of 0.0033333 s.
PERIOD_TOLERANCE = 0.002
#: The most time steps a suggested step puts in the control period.
MOST_STEPS_SUGGESTED = 100


def whole_steps(period, step, field, step_field, others=()):
    """`period` (s) as a whole multiple of `step`: itself when it is one, the nearest one
    within PERIOD_TOLERANCE, else ScenarioError with both values and a step dividing
    `period` (and each of `others`, the periods that share the step)."""
    count = _steps(period, step)
    if count is not None:
        return period if _steps(period, step, 1e-9) else count * step
    nearest = sorted({max(1, math.floor(period / step)), max(1, math.ceil(period / step))})
    divisors = (period / count for count in range(nearest[0], MOST_STEPS_SUGGESTED + 1))
    divisor = next((divisor for divisor in divisors if divisor <= step and all(
        _steps(other, divisor) is not None for other in others)), None)
    hint = (f", or a {step_field} of {divisor:.5g} s ({round(period / divisor)} steps)"
            if divisor else "")
    raise ScenarioError(
        f"{field} {period:g} s is {period / step:.4g} steps of {step_field} {step:g} s; "
        f"expected a whole multiple of it (within {PERIOD_TOLERANCE:.1%}): "
        f"{' or '.join(f'{count * step:g} s' for count in nearest)}{hint}")


def _steps(period, step, tolerance=PERIOD_TOLERANCE):
    """How many `step`s make `period` within `tolerance` of it; None if no whole number."""
    count = round(period / step)
    return count if count >= 1 and abs(period - count * step) <= tolerance * period else None
