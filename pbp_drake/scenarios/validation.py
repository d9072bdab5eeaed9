"""The checks of a scenario file, in the order loading meets them:

1. its text, before and around Drake's YAML loader (`read_scenario_text`,
   `describe_load_error`), so that every broken file ends in a message that names the file
   and the line or the field;
2. its mappings walked next to the schema (`shape_problem`), for what Drake's loader
   misreports;
3. its numbers, before anything is computed from them (`check_numbers`,
   `check_time_steps`, the seed, the tasks' ranges and counts).

Each raises (or returns the words of) a ScenarioError as `field.path: what is wrong, what is
expected`.
"""

import dataclasses
import difflib
import math
import numbers
import re
import types
import typing

import numpy as np

from pbp_drake.core.pilot_population import ParticipantPopulationParams, population_problem
from pbp_drake.core.surrogate_pilots import ProportionalPilotParams
from pbp_drake.scenarios.bounds import read_bounded
from pbp_drake.scenarios.schema import ScenarioError


# ---------------------------------------------------------------------------------------------
# 1. The file's text, before and around Drake's YAML loader.


_BLOCK_KEY = re.compile(r"^( *)((?:- +)*)([A-Za-z_][\w.-]*|\"[^\"]*\"|'[^']*') *:(?: |$)")
_MERGE_FRAME = "_merge_yaml_dict_item_into_target"


def read_scenario_text(path):
    """The file's text; raises ScenarioError (without the file's name) for a file over
    MOST_FILE_BYTES, a binary or non-UTF-8 file, a tab in the indentation or no scenario
    at all (then `check_duplicate_keys`)."""
    data = read_bounded(path)
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise ScenarioError("the file is UTF-16 encoded; save it as UTF-8 text")
    if b"\0" in data:
        raise ScenarioError("a binary file (it holds NUL bytes), not a YAML scenario file; "
                            "expected UTF-8 text")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise ScenarioError(f"byte {error.start} is not UTF-8 (a binary file?); expected "
                            "UTF-8 text") from None
    for number, line in enumerate(text.splitlines(), 1):
        indent = line[:len(line) - len(line.lstrip(" \t"))]
        if "\t" in indent and line.strip():
            raise ScenarioError(f"line {number}: a tab in the indentation; YAML indents with "
                                "spaces only")
    if all(not line.strip() or line.lstrip().startswith("#") for line in text.splitlines()):
        # Drake's loader reads an empty document as None and fails with a TypeError.
        raise ScenarioError("the file is empty; expected a scenario file starting with "
                            "`scenario:`")
    return text


def check_duplicate_keys(text):
    """Raises ScenarioError naming the line of the second of two equal keys of one mapping,
    in block mappings (by indentation) and in flow mappings `{a: 1, a: 2}`."""
    _check_flow_keys(text)
    stack = []  # (column, {key: line}) of the open block mappings, innermost last
    block_scalar = None  # the indentation a `|` or `>` scalar's lines must exceed
    flow_depths = _flow_depth_by_line(text)
    for number, line in enumerate(text.splitlines(), 1):
        stripped = line.strip()
        column = len(line) - len(line.lstrip(" "))
        if block_scalar is not None:
            if not stripped or column > block_scalar:
                continue
            block_scalar = None
        if not stripped or stripped.startswith("#") or flow_depths[number] > 0:
            continue
        match = _BLOCK_KEY.match(line)
        if not match:
            continue
        key_column = match.start(3)
        key = match.group(3).strip("\"'")
        new_item = bool(match.group(2))
        while stack and (stack[-1][0] > key_column
                         or (new_item and stack[-1][0] == key_column)):
            stack.pop()
        if not stack or stack[-1][0] < key_column:
            stack.append((key_column, {}))
        keys = stack[-1][1]
        if key in keys:
            raise ScenarioError(f"line {number}: duplicate key {key!r} (first on line "
                                f"{keys[key]}); each key may appear once in a mapping")
        keys[key] = number
        rest = line[match.end():].split(" #")[0].strip()
        if re.fullmatch(r"[|>][-+0-9]*", rest):
            block_scalar = key_column if new_item else column


def _flow_depth_by_line(text):
    """For each line (1-based), the number of `{`/`[` open at its start."""
    depths, depth, quote = [0, 0], 0, None
    for line in text.splitlines():
        depths.append(depth)
        index = 0
        while index < len(line):
            char = line[index]
            if quote:
                if char == quote:
                    quote = None
            elif char in "\"'" and (index == 0 or line[index - 1] in " ,[{:"):
                quote = char
            elif char == "#" and (index == 0 or line[index - 1] in " \t"):
                break
            elif char in "[{":
                depth += 1
            elif char in "]}":
                depth = max(depth - 1, 0)
            index += 1
    return depths


def _check_flow_keys(text):
    """Duplicate keys inside `{...}`: a key is what stands between `{` or `,` and `: `."""
    stack = []  # per open bracket: None for `[`, {key: line} for `{`
    entry = None  # (start line, characters) of the entry being read in the innermost `{`
    quote = None
    for number, line in enumerate(text.splitlines(), 1):
        for index, char in enumerate(line):
            if quote:
                if char == quote:
                    quote = None
                if entry is not None:
                    entry[1].append(char)
                continue
            if char == "#" and (index == 0 or line[index - 1] in " \t"):
                break
            if char in "\"'" and (index == 0 or line[index - 1] in " ,[{:"):
                quote = char
            if char in "[{":
                stack.append({} if char == "{" else None)
                entry = [None, []] if char == "{" else None
            elif char in "]}":
                if stack:
                    stack.pop()
                entry = None
            elif char == "," and stack and stack[-1] is not None:
                entry = [None, []]
            elif (char == ":" and entry is not None and stack and stack[-1] is not None
                  and line[index + 1:index + 2] in ("", " ", ",", "}")):
                key = "".join(entry[1]).strip().strip("\"'")
                keys = stack[-1]
                where = entry[0] or number
                if key in keys:
                    raise ScenarioError(f"line {where}: duplicate key {key!r} (first on line "
                                        f"{keys[key]}); each key may appear once in a mapping")
                keys[key] = where
                entry = None
            elif entry is not None:
                if entry[0] is None and not char.isspace():
                    entry[0] = number
                entry[1].append(char)
        if entry is not None:
            entry[1].append(" ")


def describe_load_error(error):
    """What `yaml_load_typed` raised, as `line L, column C: ...` (a YAML syntax error) or
    `field.path: what is wrong; expected ...` (a value of the wrong type)."""
    mark = getattr(error, "problem_mark", None)
    if mark is not None:
        problem = getattr(error, "problem", None) or str(error)
        context = getattr(error, "context", None)
        context_mark = getattr(error, "context_mark", None)
        where = (f" ({context} at line {context_mark.line + 1}, column "
                 f"{context_mark.column + 1})" if context and context_mark else "")
        return (f"line {mark.line + 1}, column {mark.column + 1}: YAML syntax error: "
                f"{problem}{where}")
    names, frame = [], None
    traceback = error.__traceback__
    while traceback is not None:
        if traceback.tb_frame.f_code.co_name == _MERGE_FRAME:
            frame = traceback.tb_frame.f_locals
            if not names or names[-1] != str(frame.get("name")):  # a Union: one field twice
                names.append(str(frame.get("name")))
        traceback = traceback.tb_next
    if frame is None:
        return f"{type(error).__name__}: {error}"
    value = frame.get("yaml_value")
    given = "nothing (an empty value)" if value is None else f"{value!r}"
    return (f"{'.'.join(names)}: got {given}; expected "
            f"{_describe_schema(frame.get('value_schema'))}")


def _describe_schema(schema):
    optional = typing.get_args(schema) if typing.get_origin(schema) is typing.Union else ()
    inner = [arg for arg in optional if arg is not type(None)]
    if len(inner) == 1:
        schema = inner[0]
    names = {float: "a number", int: "an integer", str: "a string", bool: "true or false"}
    if schema in names:
        return names[schema]
    origin = typing.get_origin(schema)
    if origin in (list, tuple, typing.List):
        args = typing.get_args(schema)
        return f"a list, each item {_describe_schema(args[0])}" if args else "a list"
    if origin is dict:
        return "a mapping"
    if dataclasses.is_dataclass(schema):
        return f"a mapping of the fields of {schema.__name__}"
    return f"a value of type {schema}"


# ---------------------------------------------------------------------------------------------
# 2. The file's mappings walked next to its schema, for what Drake's loader misreports.


def shape_problem(data, schema):
    """`field.path: what is wrong; expected ...` for the first unknown key, or value that
    is not a mapping where the schema has one, of the YAML document `data` (as
    `bounds.load_document` reads it) read as `schema`; None when there is none."""
    if not isinstance(data, dict):
        return None
    return _first_problem(data, schema, "")


def _field_types(schema):
    """{name: type} of a dataclass or of a Drake config struct, None for anything else."""
    if dataclasses.is_dataclass(schema):
        try:
            hints = typing.get_type_hints(schema)
        except Exception:  # noqa: BLE001 - an annotation that does not resolve: as written
            hints = {}
        return {field.name: hints.get(field.name, field.type)
                for field in dataclasses.fields(schema)}
    fields = getattr(schema, "__fields__", None)
    if fields is not None and isinstance(schema, type):
        return {field.name: field.type for field in fields}
    return None


def _members(schema):
    """The types a Union (or Optional) field can hold, without None; [schema] otherwise."""
    if typing.get_origin(schema) not in (typing.Union, types.UnionType):
        return [schema]
    return [member for member in typing.get_args(schema) if member is not type(None)]


def _variant(schema, node):
    """The schema a node is read as: a Union's member chosen by the node's tag (the first
    member when untagged, as Drake's loader does); None for an unknown tag."""
    members = _members(schema)
    tag = node.get("_tag", "").lstrip("!") if isinstance(node, dict) else ""
    for member in members:
        if tag and getattr(member, "__name__", "") == tag:
            return member
    return members[0] if members and not tag else None


def _mapping_expected(schema, node, field):
    names = [member.__name__ for member in _members(schema)]
    if len(names) == 1:
        expected = f"a mapping of the fields of {names[0]}"
    else:
        expected = (f"a mapping, tagged with one of {', '.join('!' + n for n in names)} "
                    f"(untagged: {names[0]})")
    given = "nothing (an empty value)" if node is None else f"{node!r}"
    return f"{field}: got {given}; expected {expected}"


def _unknown_tag(schema, node, field):
    """`field: the tag !X is unknown; ...` (with did-you-mean) for a node whose tag names
    none of the Union's members, else None."""
    tag = node.get("_tag", "") if isinstance(node, dict) else ""
    if not tag:
        return None
    tags = ["!" + getattr(member, "__name__", "") for member in _members(schema)]
    matches = difflib.get_close_matches(tag, tags, n=1)
    hint = f" (did you mean {matches[0]}?)" if matches else ""
    return f"{field}: the tag {tag} is unknown; expected one of {', '.join(tags)}{hint}"


def _first_problem(node, schema, field):
    optional = type(None) in typing.get_args(schema)
    variant = _variant(schema, node)
    if variant is None:
        return _unknown_tag(schema, node, field)
    if node is None and optional:
        return None
    types_of = _field_types(variant)
    if types_of is not None:
        if not isinstance(node, dict):
            return _mapping_expected(schema, node, field or "the file's top level")
        for key, value in node.items():
            if key == "_tag":
                continue
            if key not in types_of:
                return _unknown_key(field, key, list(types_of))
            found = _first_problem(value, types_of[key], f"{field}.{key}" if field else key)
            if found:
                return found
    elif isinstance(node, list) and typing.get_origin(variant) is list:
        for index, item in enumerate(node):
            found = _first_problem(item, typing.get_args(variant)[0], f"{field}[{index}]")
            if found:
                return found
    return None


def _unknown_key(field, key, known):
    matches = difflib.get_close_matches(key, [name for name in known if name != key], n=1)
    suggestion = f" (did you mean {matches[0]!r}?)" if matches else ""
    where = field or "the file's top level"
    return (f"{where}: unknown key {key!r}{suggestion}; expected one of "
            f"{', '.join(sorted(known))}")


# ---------------------------------------------------------------------------------------------
# 3. The numbers, before anything is computed from them.


# No length, time, gain or speed of a scenario comes near this; beyond it a norm or a
# square overflows (1e300 squared is inf) and numpy answers with warnings and NaN.
LARGEST_NUMBER = 1e12
# The shortest time step (s) a scenario may ask for: a simulated second then takes a
# million steps; a smaller one (1e-300 passes every "positive" check) never ends.
SHORTEST_TIME_STEP = 1e-6
# The longest a DMP may last (s); a far goal over a tiny robot.speed would otherwise give
# a duration whose square overflows in the DMP's gains.
LONGEST_DMP_DURATION = 1e6
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
        if not (np.isfinite(value) and (value > 0 if positive else value >= 0)):
            raise ScenarioError(f"{field}.{name} must be finite and {least}, got {value}")


def check_time_steps(time_steps):
    """`time_steps`: (field, value) pairs, each at least SHORTEST_TIME_STEP."""
    for field, value in time_steps:
        if not value >= SHORTEST_TIME_STEP:
            raise ScenarioError(f"{field} {value:g} s is too short; expected at least "
                                f"{SHORTEST_TIME_STEP:g} s")


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
    check_range(task, "scenario.task", "object_count")
    # Objects are placed min_separation apart in front of the robot: a few dozen fit.
    check_count(task.object_count[0], "scenario.task.object_count[0]", 1, 100)
    check_count(task.object_count[1], "scenario.task.object_count[1]", 1, 100)
    check_switch_schedule(task)


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
    for name in ("x_range", "y_range", "object_count"):
        check_range(task, field, name)
    check_count(task.object_count[0], f"{field}.object_count[0]", 1, 100)
    check_count(task.object_count[1], f"{field}.object_count[1]", 1, 100)
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
                   ("success_distance", "obstacle_radius", "obstacle_height", "obstacle_speed",
                    "obstacle_spacing"))
    # Obstacles start 0.45 m from each other, the robot and the target: a few dozen fit.
    # Without any, the station has no obstacle input for the task to drive.
    check_count(task.obstacle_count, "scenario.task.obstacle_count", 1, 100,
                " (a task without obstacles is the reaching task: an untagged task)")
    for name in ("x_range", "y_range", "obstacle_x_range", "obstacle_y_range"):
        check_range(task, "scenario.task", name)
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
    (`VirtualParticipantParams`): what it divides by (`slow_radius`,
    `turn_slowdown_angle`), times, rates and steps positive, other distances, angles,
    times, weights and factors not negative,
    `plan_directions` a count and `plan_times` positive times that increase; and its
    `impairment` (`ParticipantImpairment.problem`: levels and times finite and not
    negative, a probability in [0, 1])."""
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
