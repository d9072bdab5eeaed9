"""The flags that change a scenario file's fields: `--set FIELD=VALUE`, `--scenario-text
YAML` (`scenarios.overrides`) and the shorthands, each one `--set`."""

from pbp_drake.scenarios import (
    METHODS, OPERATOR_NAMES, MultiGoalReach, ScenarioError, TaskScenario, load_scenario_file,
    parse_method_label)
from pbp_drake.core.choices import unknown_choice
from pbp_drake.scenarios.bounds import MAX_GOALS
from pbp_drake.scenarios.overrides import ScenarioOverrides


def add_override_flags(parser):
    """`--set` and `--scenario-text`."""
    group = parser.add_argument_group(
        "scenario fields", "change the file's fields as the file would: FIELD is a dotted "
        "path under `scenario:` (`study.FIELD` under `study:`), VALUE read as YAML")
    group.add_argument("--set", action="append", default=[], metavar="FIELD=VALUE",
                       dest="settings", help="e.g. --set goal_estimator.method=nearest "
                       "--set control_period=0.02 (repeatable; applied after the text)")
    group.add_argument("--scenario-text", metavar="YAML",
                       help="a mapping of fields merged onto the file, e.g. "
                       "'{seed: 3, goal_estimator: {method: nearest}}'")
    return group


def add_shorthand_flags(group):
    """`--method`, `--operator`, `--seed`, `--duration` and `--alpha`, in `group`."""
    group.add_argument("--method", help=f"--set method=METHOD: {', '.join(METHODS)} "
                       "(fixed_alpha=A sets alpha too)")
    group.add_argument("--operator", help="--set operator=...: who drives a task, one of "
                       f"{', '.join(OPERATOR_NAMES)} (keyboard and gamepad: in the browser)")
    group.add_argument("--seed", type=int, help="--set seed=N: the scene's and the noise's seed")
    group.add_argument("--duration", type=float, metavar="SECONDS",
                       help="--set duration=SECONDS (for a task, its time limit)")
    group.add_argument("--alpha", type=float, help="--set alpha=A (fixed_alpha's weight)")


def add_goals_flag(group):
    """`--goals K`, in `group`."""
    group.add_argument("--goals", type=int, metavar="K",
                       help="--set task.grid_objects=K: a reaching task's K objects "
                       f"(candidate goals, up to {MAX_GOALS:,}), one in each cell of a grid "
                       "over its region, drawn from each scene's seed")


def add_hardware_flags(group):
    """`--hardware` and `--driver-sim`, in `group`."""
    group.add_argument("--hardware", action="store_true",
                       help="--set robot.hardware.connect=true: drive the real arm through its "
                       "Drake LCM driver (robot: !Arm with hardware: {driver: panda|iiwa}), in "
                       "real time")
    group.add_argument("--driver-sim", action="store_true",
                       help="--set robot.hardware.driver_sim=true: with --hardware, the "
                       "driver simulator in this process, on a memq:// bus of its own")


OPERATOR_ON_A_SCENE = ("--operator chooses who drives the tasks; this scenario uses the 2-D "
                       "toy robot")


def load_with_overrides(args, overrides):
    """`load_scenario_file` of `args.scenario` with `overrides` (`scenario_overrides(args)`).
    A flag the file cannot take at all fails as the field it sets (an unknown tag or key,
    or a field that needs another), so on a failure it is named instead: `--operator` on a
    2-D scene, `--goals` outside the reaching task."""
    try:
        return load_scenario_file(args.scenario, overrides)
    except ScenarioError:
        operator = getattr(args, "operator", None) is not None
        if not operator and getattr(args, "goals", None) is None:
            raise
        scenario = load_scenario_file(args.scenario).scenario  # the file's own error, if any
        if not isinstance(scenario, TaskScenario):
            raise ScenarioError(OPERATOR_ON_A_SCENE if operator else
                                "--goals places a reaching task's objects; this scenario uses "
                                "the 2-D toy robot") from None
        if getattr(args, "goals", None) is not None and not isinstance(scenario.task,
                                                                       MultiGoalReach):
            raise ScenarioError(f"--goals places a reaching task's objects; this scenario's "
                                f"task is !{type(scenario.task).__name__}") from None
        raise


def scenario_overrides(args, shorthands=True):
    """The overrides of the parsed `args`: the text, the shorthands (`shorthands` False:
    `study`'s `--seed` is not a field), `--goals`, then each `--set`."""
    shorthands = _shorthand_settings(args) if shorthands else []
    goals = getattr(args, "goals", None)
    if goals is not None:
        if goals == 0:  # task.grid_objects 0 is the task's own objects: not what K asks
            raise ScenarioError("--goals must be positive, got 0")
        shorthands.append((f"task.grid_objects={goals}", f"--goals {goals}"))
    return ScenarioOverrides(
        tuple(setting for setting, _ in shorthands) + tuple(args.settings),
        args.scenario_text, tuple(typed for _, typed in shorthands))


def _shorthand_settings(args):
    """[(FIELD=VALUE, the flag as typed)] of the shorthands (on `run` and `session`) given."""
    settings = []
    if args.method is not None:
        name, alpha = parse_method_label(args.method)
        settings.append((f"method={name}", f"--method {args.method}"))
        if alpha is not None:
            settings.append((f"alpha={alpha!r}", f"--method {args.method}"))
    if args.operator is not None:
        if args.operator not in OPERATOR_NAMES:
            raise ScenarioError(unknown_choice("--operator", args.operator, OPERATOR_NAMES))
        # A tag: the file's operator of the same kind keeps its settings (`merged`).
        settings.append((f"operator=!{OPERATOR_NAMES[args.operator].__name__} {{}}",
                         f"--operator {args.operator}"))
    for flag in ("seed", "duration", "alpha"):
        value = getattr(args, flag)
        if value is not None:
            settings.append((f"{flag}={value!r}", f"--{flag} {value:g}"))
    for flag, field in (("hardware", "connect"), ("driver_sim", "driver_sim")):
        if getattr(args, flag):
            settings.append((f"robot.hardware.{field}=true", f"--{flag.replace('_', '-')}"))
    return settings
