"""Reading a scenario (`load_scenario_file`, `load_scenario_text`): its text within bounds
(`bounds`), its YAML document walked next to the schema (unknown keys and tags, values of the
wrong kind, each named by its field), read into the schema by Drake's typed loader, then
resolved (`resolve`, which checks the values) and its study checked.
"""

import dataclasses
import difflib
import filecmp
import os
import pathlib
import types
import typing

import numpy as np

from pbp_drake.core.choices import did_you_mean
from pbp_drake.scenarios.bounds import (
    check_yaml_bounds, is_special_file, load_document, load_typed, read_bounded)
from pbp_drake.scenarios.overrides import ScenarioOverrides, merged
from pbp_drake.scenarios.resolution import (
    ResolvedScenario, check_obstacles, demonstration_samples, resolve, with_method)
from pbp_drake.scenarios.schema import (
    HSR_OPERATORS, RANGE, STUDY_SPLITS, TOY_OPERATORS, AlphaStudy, AltVsCont, Arm, alpha_key,
    MethodComparison, PointRobot, PointScenario, Scenario, ScenarioError, ScenarioFile,
    TaskScenario, TaskScenarioFile)
from pbp_drake.scenarios.validation import check_numbers, check_seed


@dataclasses.dataclass(frozen=True)
class LoadedScenarioFile:
    """A scenario read and resolved: its `scenario` and `study` configs as written, and
    `resolved`, the scenario with everything derived (see `resolve`). `path` is the file
    read, None for a scenario given as text."""

    path: typing.Optional[pathlib.Path]
    scenario: Scenario
    study: typing.Any
    resolved: ResolvedScenario


def load_scenario_file(path, overrides=None):
    """Reads, checks and resolves a scenario file (see `load_scenario_text`, the folder the
    file's). `overrides` (a `ScenarioOverrides`: the command line's `--set` and
    `--scenario-text`) are merged onto the file's document first and checked as the file
    is; errors then name the file and the overrides."""
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a scenario file's path, a str or os.PathLike; got "
                        f"{path!r}")
    if not isinstance(overrides, (ScenarioOverrides, type(None))):
        raise TypeError(f"overrides must be a pbp_drake.ScenarioOverrides (e.g. "
                        f"ScenarioOverrides(settings=('duration=2.0',)), as --set) or None; got "
                        f"{overrides!r}")
    if not os.fspath(path):  # pathlib would read it as ".", the current folder
        raise ScenarioError("the scenario file's path is empty; expected a file such as "
                            "diagrams/hsr_reach.yaml")
    path = pathlib.Path(path)
    if path.is_dir():
        raise ScenarioError(f"{path}: is a folder; expected a scenario file such as "
                            "diagrams/hsr_reach.yaml")
    if is_special_file(path):
        raise ScenarioError(f"{path}: is not a regular file (a device or a pipe); expected a "
                            "scenario file such as diagrams/hsr_reach.yaml")
    if not path.is_file():
        raise ScenarioError(f"{path}: no such scenario file")
    try:
        text = decode_scenario_bytes(read_bounded(path))
    except ScenarioError as error:
        raise ScenarioError(f"{path}: {error}") from None
    origin, overlays = str(path), ()
    if overrides:
        origin, overlays = f"{path} with {overrides.words()}", (overrides.overlay(),)
    return dataclasses.replace(
        load_scenario_text(text, origin, path.parent, overlays), path=path)


def load_scenario_text(text, origin="scenario text", folder=None, overlays=()):
    """Reads, checks and resolves the YAML `text` of a scenario file; each of `overlays`
    (YAML text of a mapping, e.g. ``scenario: {task: {object_count: 5}}``, or such a
    mapping as `bounds.load_document` reads it) is merged into the document first
    (`overrides.merged`). Raises ScenarioError as `ORIGIN: field.path: what is wrong` (or
    `line L`). A relative arm `model_file` and `dmp.primitive` are read from `folder`
    (default: the working folder)."""
    primitive_typed = False  # `dmp.primitive` given on the command line
    try:
        document = _document(text)
        for overlay in overlays:
            if isinstance(overlay, dict):
                primitive_typed = primitive_typed or _sets_primitive(overlay)
                document = merged(document, overlay)
                continue
            try:
                parsed = _document(overlay, "the override")
                document = merged(document, parsed)
            except ScenarioError as error:
                raise ScenarioError(f"the override {overlay.strip()!r}: {error}") from None
            primitive_typed = primitive_typed or _sets_primitive(parsed)
        schema = file_schema(document)
        problem = _first_problem(document, schema, "")
        if problem:
            raise ScenarioError(problem)
        if "scenario" not in document:  # not each field's default, blamed on another
            raise ScenarioError("the file has no `scenario:` section; expected a mapping with "
                                "`scenario:` (and optionally `study:`)")
        loaded = load_typed(schema, document)
    except ScenarioError as error:
        raise ScenarioError(f"{origin}: {error}") from None
    except Exception as error:  # noqa: BLE001 - what the YAML loader raises for bad input
        raise ScenarioError(f"{origin}: {type(error).__name__}: {error}") from None
    try:
        scenario = _paths_from(loaded.scenario, folder, primitive_typed)
        resolved = resolve(scenario)
        check_numbers(loaded.study, "study")
        if resolved.has_task and not isinstance(loaded.study, (MethodComparison, type(None))):
            raise ScenarioError(f"study !{type(loaded.study).__name__} varies a 2-D scene; a "
                                "robot task takes study: !MethodComparison")
        if isinstance(loaded.study, AlphaStudy):
            check_alpha_study(loaded.study, scenario, resolved.start.size)
        if isinstance(loaded.study, MethodComparison):
            check_method_comparison(loaded.study, scenario)
        if isinstance(loaded.study, AltVsCont):
            check_goal_tolerance(loaded.study)
    except ScenarioError as error:
        raise ScenarioError(f"{origin}: {error}") from None
    return LoadedScenarioFile(path=None, scenario=scenario, study=loaded.study,
                              resolved=resolved)


def file_schema(document):
    """The file's type for its parsed YAML `document`: `TaskScenarioFile` when its
    `scenario.robot` has a tag but `!PointRobot` (`!Hsr`, `!Arm`, or one the walk then
    names with those it takes); `ScenarioFile` (a 2-D scene) when the robot is
    `!PointRobot` or an untagged mapping of the point robot's fields. Otherwise (no robot,
    an untagged HSR as `yaml_dump_typed` writes it, a value of the wrong kind) a robot task
    when the scenario has a task's operator, or holds what only a robot task has (a task,
    likely paths, a seed) and nothing only a 2-D scene has (goals, a start, obstacles, a
    demonstration); else a 2-D scene."""
    scenario = document.get("scenario")
    if not isinstance(scenario, dict):
        return ScenarioFile
    robot = scenario.get("robot")
    if isinstance(robot, dict):
        tag = robot.get("_tag", "")
        if tag:
            return ScenarioFile if tag == "!PointRobot" else TaskScenarioFile
        if robot and set(robot) <= set(_field_types(PointRobot)):
            return ScenarioFile
    operator = scenario.get("operator")
    operator_tag = operator.get("_tag", "") if isinstance(operator, dict) else ""
    task_fields, point_fields = set(_field_types(TaskScenario)), set(_field_types(PointScenario))
    if operator_tag in _TASK_OPERATOR_TAGS or (
            (task_fields - point_fields) & set(scenario)
            and not (point_fields - task_fields) & set(scenario)):
        return TaskScenarioFile
    return ScenarioFile


_TASK_OPERATOR_TAGS = {"!" + cls.__name__ for cls in HSR_OPERATORS if cls not in TOY_OPERATORS}


# A key of the other scenario type, said with what it belongs to.
_OTHER_TYPE = {
    PointScenario: (TaskScenario, " (a robot task's field: give robot: !Hsr {...} or "
                                  "!Arm {...})"),
    TaskScenario: (PointScenario, " (a 2-D scene's field: a robot task draws its goals, the "
                                  "objects, from its task and starts where the robot stands)")}


def decode_scenario_bytes(data):
    """The text of a scenario file's bytes; ScenarioError for UTF-16, a binary file or bytes
    that are not UTF-8."""
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise ScenarioError("the file is UTF-16 encoded; save it as UTF-8 text")
    if b"\0" in data:
        raise ScenarioError("a binary file (it holds NUL bytes), not a YAML scenario file; "
                            "expected UTF-8 text")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise ScenarioError(f"byte {error.start} is not UTF-8 (a binary file?); expected "
                            "UTF-8 text") from None


def _document(text, what="the file"):
    """The YAML document of `text`, its size and aliases bounded; a mapping."""
    for number, line in enumerate(text.splitlines(), 1):
        if "\t" in line[:len(line) - len(line.lstrip(" \t"))] and line.strip():
            raise ScenarioError(f"line {number}: a tab in the indentation; YAML indents with "
                                "spaces only")
    if all(not line.strip() or line.lstrip().startswith("#") for line in text.splitlines()):
        raise ScenarioError(f"{what} is empty; expected a scenario file starting with "
                            "`scenario:`")
    # Before any value is made: a few lines of aliases can stand for billions.
    check_yaml_bounds(text)
    try:
        document = load_document(text)
    except ScenarioError:
        raise
    except Exception as error:  # noqa: BLE001 - PyYAML's errors for text that does not parse
        raise ScenarioError(_syntax_error(error)) from None
    if not isinstance(document, dict):
        raise ScenarioError(f"{what}'s top level holds {_given(document)}; expected a "
                            "mapping with `scenario:` (and optionally `study:`)")
    return document


def _syntax_error(error):
    mark = getattr(error, "problem_mark", None)
    if mark is None:
        return f"YAML error: {error}"
    context, context_mark = getattr(error, "context", None), getattr(error, "context_mark", None)
    where = (f" ({context} at line {context_mark.line + 1}, column {context_mark.column + 1})"
             if context and context_mark else "")
    return (f"line {mark.line + 1}, column {mark.column + 1}: YAML syntax error: "
            f"{getattr(error, 'problem', None) or error}{where}")


def _paths_from(scenario, folder, primitive_typed=False):
    """`scenario` with a relative arm model file and `dmp.primitive` made paths from
    `folder` (None: the working folder). A relative `dmp.primitive` that names no file
    there but one from the working folder, or that was typed on the command line
    (`primitive_typed`) and names another file from the working folder, is refused."""
    robot, primitive = scenario.robot, scenario.dmp.primitive
    folder = os.path.abspath(folder or os.curdir)
    if (isinstance(robot, Arm) and robot.model_file and "://" not in robot.model_file
            and not os.path.isabs(robot.model_file)):
        robot = dataclasses.replace(robot, model_file=os.path.join(folder, robot.model_file))
        scenario = dataclasses.replace(scenario, robot=robot)
    if primitive and not os.path.isabs(primitive):
        read = os.path.join(folder, primitive)
        _check_primitive_folder(primitive, folder, primitive_typed)
        scenario = dataclasses.replace(scenario,
                                       dmp=dataclasses.replace(scenario.dmp, primitive=read))
    return scenario


def _check_primitive_folder(primitive, folder, typed):
    """Refuses the relative `dmp.primitive`, read from the scenario file's `folder`, when
    the same path from the working folder is a file it would not read: there is none in
    the scenario's folder, or (`typed` on the command line, where a path is read from the
    working folder elsewhere) another file is."""
    here, read = os.path.abspath(primitive), os.path.join(folder, primitive)
    if here == read or not os.path.isfile(here):
        return
    there = os.path.isfile(read)
    if there and (not typed or _same_bytes(here, read)):
        return
    other = f"give {os.path.relpath(here, folder)} or its absolute path"
    if not there:
        raise ScenarioError(f"scenario.dmp.primitive {primitive}: a relative path is read "
                            f"from the scenario file's folder, {folder}, which has no such "
                            f"file; for the working folder's, {other}")
    raise ScenarioError(f"scenario.dmp.primitive {primitive} is read from the scenario "
                        f"file's folder, as {read}; the working folder has another "
                        f"{primitive}: for that one, {other}; for the first, its absolute "
                        "path")


def _same_bytes(one, other):
    try:
        return os.path.samefile(one, other) or filecmp.cmp(one, other, shallow=False)
    except OSError:
        return False


def _sets_primitive(overlay):
    """Whether the override document `overlay` sets `scenario.dmp.primitive`."""
    scenario = overlay.get("scenario")
    dmp = scenario.get("dmp") if isinstance(scenario, dict) else None
    return isinstance(dmp, dict) and "primitive" in dmp


# ---------------------------------------------------------------------------------------------
# The document walked next to the schema: what Drake's loader refuses without naming the
# field (or accepts), said with the field's path.


_KINDS = {float: ("a number", (int, float)), int: ("an integer", (int,)),
          str: ("a string", (str,)), bool: ("true or false", (bool,))}


def _field_types(schema):
    """{name: (type, is a range)} of a dataclass or a Drake config struct; None for others."""
    if dataclasses.is_dataclass(schema):
        hints = typing.get_type_hints(schema)
        return {field.name: (hints[field.name], field.metadata.get(RANGE, False))
                for field in dataclasses.fields(schema)}
    fields = getattr(schema, "__fields__", None)
    if fields is not None and isinstance(schema, type):
        return {field.name: (field.type, False) for field in fields}
    return None


def _members(schema):
    """The types a Union (or Optional) field can hold, without None; [schema] otherwise."""
    if typing.get_origin(schema) not in (typing.Union, types.UnionType):
        return [schema]
    return [member for member in typing.get_args(schema) if member is not type(None)]


def _given(node):
    if node is None:
        return "nothing (an empty value)"
    return f"a list {node!r}" if isinstance(node, list) else repr(node)


def _first_problem(node, schema, field, is_range=False):
    """`field.path: what is wrong; expected ...` of the first node of `node` that `schema`
    cannot hold, None when there is none. A range field given one number is made the
    range [number, number] in place."""
    members = _members(schema)
    if node is None and type(None) in typing.get_args(schema):
        return None
    tag = node.get("_tag", "") if isinstance(node, dict) else ""
    names = [getattr(member, "__name__", str(member)) for member in members]
    variant = next((m for m, n in zip(members, names) if tag == "!" + n), None)
    if tag and members == [schema]:  # a field of one type: Drake reads no tag there
        return f"{field}: {names[0]} is written without a tag; drop {tag}"
    if tag and variant is None:
        tags = ["!" + name for name in names]
        matches = difflib.get_close_matches(tag, tags, n=1)
        hint = f" (did you mean {matches[0]}?)" if matches else ""
        return f"{field}: the tag {tag} is unknown; expected one of {', '.join(tags)}{hint}"
    variant = variant or members[0]
    types_of = _field_types(variant)
    where = field or "the file's top level"
    if types_of is not None:
        if not isinstance(node, dict):
            expected = (f"a mapping of the fields of {names[0]}" if len(names) == 1 else
                        f"a mapping, tagged with one of {', '.join('!' + n for n in names)} "
                        f"(untagged: {names[0]})")
            return f"{where}: got {_given(node)}; expected {expected}"
        for key, value in node.items():
            if key == "_tag" or (not field and str(key).startswith("_")):
                continue  # the top level's private keys hold anchors' templates
            if key not in types_of:
                other, belongs = _OTHER_TYPE.get(variant, (None, ""))
                hint = (belongs if other is not None and key in _field_types(other)
                        else did_you_mean(key, types_of))
                return (f"{where}: unknown key {key!r}{hint}; "
                        f"expected one of {', '.join(sorted(types_of))}")
            value_type, is_range = types_of[key]
            if is_range and isinstance(value, (int, float)) and not isinstance(value, bool):
                node[key] = value = [value, value]
            found = _first_problem(value, value_type, f"{field}.{key}" if field else str(key),
                                   is_range)
            if found:
                return found
        return None
    if typing.get_origin(variant) is list:
        if not isinstance(node, list):
            single = " (or one number: exactly it)" if is_range else ""
            return f"{field}: got {_given(node)}; expected a list{single}"
        item_type = typing.get_args(variant)[0]
        return next(filter(None, (_first_problem(item, item_type, f"{field}[{index}]")
                                  for index, item in enumerate(node))), None)
    if variant in _KINDS:
        words, kinds = _KINDS[variant]
        if variant is float and isinstance(node, str) and _reads_as_float(node):
            return None  # as Drake's loader reads it: YAML 1.1 takes 1.0e9 for a string
        if isinstance(node, bool) != (variant is bool) or not isinstance(node, kinds):
            return f"{field}: got {_given(node)}; expected {words}"
    return None


def _reads_as_float(text):
    try:
        float(text)
    except ValueError:
        return False
    return True


# ---------------------------------------------------------------------------------------------
# The study sections.


def check_alpha_study(study, scenario, dimension):
    """The alpha study's scenes and alphas, for a scenario of `dimension` (2 for the
    paper's toy)."""
    if not study.scenes:
        raise ScenarioError("study.scenes is empty")
    if not study.alphas:
        raise ScenarioError("study.alphas is empty")
    for alpha in study.alphas:
        if not (np.isfinite(alpha) and 0.0 <= alpha <= 1.0):
            raise ScenarioError(f"study.alphas has {alpha}, outside [0, 1]")
    # The summary keys each alpha's results by it: a second one would overwrite the first's.
    keys = [alpha_key(alpha) for alpha in study.alphas]
    for index, key in enumerate(keys):
        if keys.index(key) != index:
            raise ScenarioError(f"study.alphas has {key} twice; give each alpha once")
    if scenario.demonstration is None:
        raise ScenarioError("the alpha study needs scenario.demonstration")
    # Explicit arbitration plays the demonstration to its end: with the goal elsewhere, which
    # PBP's DMPs reach, every alpha would fall short of it.
    if scenario.goals:
        end = np.round(demonstration_samples(scenario.demonstration)[1][-1], 6)
        if not np.allclose(scenario.goals, [end]):
            raise ScenarioError(f"scenario.goals {scenario.goals} is not where "
                                f"scenario.demonstration ends, {end.tolist()}: the alpha "
                                "study plays the demonstration as P; move its goal instead")
    check_operator_speeds(study, scenario)
    names = [scene.name for scene in study.scenes]
    for index, scene in enumerate(study.scenes):
        if not scene.name:
            raise ScenarioError(f"study.scenes[{index}] needs a name")
        if names.index(scene.name) != index:
            raise ScenarioError(f"study.scenes[{index}]: the name {scene.name!r} is taken by "
                                f"study.scenes[{names.index(scene.name)}]; give each scene "
                                "its own")
        check_obstacles(scene.obstacles, dimension, f"study.scenes[{index}].obstacles")


def check_operator_speeds(study, scenario):
    """The alpha study's `operator_speeds` (each the virtual operator's `speed`) and its
    goal tolerance."""
    check_goal_tolerance(study)
    if not study.operator_speeds:
        return
    if not hasattr(scenario.operator, "speed"):
        raise ScenarioError(f"study.operator_speeds needs an operator with a speed, not "
                            f"!{type(scenario.operator).__name__}")
    for speed in study.operator_speeds:
        if not (np.isfinite(speed) and speed >= 0):
            raise ScenarioError(f"study.operator_speeds has {speed}: speeds are finite, >= 0")
    # The summary keys results by the speed written with %g: two speeds must not share one.
    keys = [f"{speed:g}" for speed in study.operator_speeds]
    if len(set(keys)) != len(keys):
        raise ScenarioError(f"study.operator_speeds repeats a speed: {study.operator_speeds}")


def check_goal_tolerance(study):
    """A toy study's `goal_tolerance` (m), within which a run's end reached the goal: at or
    below 0 no run would."""
    if not (np.isfinite(study.goal_tolerance) and study.goal_tolerance > 0):
        raise ScenarioError(f"study.goal_tolerance must be positive, got {study.goal_tolerance}")


def check_method_comparison(study, scenario):
    if not isinstance(scenario, TaskScenario):
        raise ScenarioError("study !MethodComparison runs the tasks: use robot: !Hsr or "
                            "!Arm")
    if not study.methods:
        raise ScenarioError("study.methods is empty")
    if len(set(study.methods)) != len(study.methods):
        raise ScenarioError(f"study.methods {study.methods} names a method twice")
    for method in study.methods:
        try:
            with_method(scenario, method)
        except ScenarioError as error:
            raise ScenarioError(f"study.methods: {error}") from None
    if study.trials < 1:
        raise ScenarioError(f"study.trials must be at least 1, got {study.trials}")
    check_seed(study.tuning_seed, "study.tuning_seed")
    check_seed(study.evaluation_seed, "study.evaluation_seed")
    if study.evaluation_seed <= study.tuning_seed:
        raise ScenarioError(f"study.evaluation_seed {study.evaluation_seed} is not above "
                            f"study.tuning_seed {study.tuning_seed}; expected the evaluation "
                            "seeds after the tuning seeds")
    if study.split not in STUDY_SPLITS:
        raise ScenarioError(f"study.split {study.split!r} is unknown; expected one of "
                            f"{', '.join(STUDY_SPLITS)}")
