"""Reading a scenario file: its size and YAML bounded (`bounds`), parsed once by PyYAML's C
loader, read into the schema by Drake's typed loader, then resolved (which checks it).

Unknown or misspelled keys are errors that name the key (with a suggestion); values are
checked by `resolve`, and a study section by the checks here.
"""

import dataclasses
import pathlib
import re
import typing

import numpy as np

from pbp_drake.scenarios.bounds import check_yaml_bounds, load_document, load_typed
from pbp_drake.scenarios.overrides import document_text
from pbp_drake.scenarios.resolution import (
    ResolvedScenario, check_obstacles, resolve, with_method)
from pbp_drake.scenarios.schema import (
    AlphaStudy, MethodComparison, Scenario, ScenarioError, TASK_ROBOTS,
    STUDY_SPLITS, ScenarioFile)
from pbp_drake.scenarios.validation import (
    check_duplicate_keys, check_numbers, check_seed, describe_load_error,
    read_scenario_text, shape_problem)


@dataclasses.dataclass(frozen=True)
class LoadedScenarioFile:
    """A scenario file read and resolved: its `scenario` and `study` configs as written, and
    `resolved`, the scenario with everything derived (see `resolve`)."""

    path: pathlib.Path
    scenario: Scenario
    study: typing.Any
    resolved: ResolvedScenario


def load_scenario_file(path, overrides=None):
    """Reads, checks and resolves a scenario file; errors name the file and the field.
    `overrides` (`overrides.ScenarioOverrides`: the command line's `--set` and
    `--scenario-text`) are merged onto the file's document before it is read, and checked
    as the file is; errors then name the file and the overrides."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise ScenarioError(f"{path}: no such scenario file")
    try:
        text = read_scenario_text(path)
    except ScenarioError as error:
        raise ScenarioError(f"{path}: {error}") from None
    return load_scenario_text(text, path, overrides)


def load_scenario_text(text, path, overrides=None):
    """`load_scenario_file` of a scenario file's `text`, named `path` in its errors."""
    try:
        # Before any value is made (a few lines of aliases can stand for billions), and
        # before the slower walk of the text for duplicate keys.
        check_yaml_bounds(text)
        check_duplicate_keys(text)
    except ScenarioError as error:
        raise ScenarioError(f"{path}: {error}") from None
    try:
        document = load_document(text)
    except Exception as error:  # noqa: BLE001 - what the YAML loader raises for bad input
        raise ScenarioError(f"{path}: {_load_error_message(error)}") from None
    origin = path
    if overrides:
        document = overrides.apply(document)
        text = document_text(document)
        origin = f"{path} with {overrides.words()}"
    # Before the typed loader: it accepts some of these and misreports the others.
    problem = shape_problem(document, ScenarioFile)
    if problem:
        raise ScenarioError(f"{origin}: {problem}")
    try:
        loaded = load_typed(ScenarioFile, document, text)
    except Exception as error:  # noqa: BLE001 - what the YAML loader raises for bad input
        raise ScenarioError(f"{origin}: {_load_error_message(error)}") from None
    try:
        resolved = resolve(loaded.scenario)
        check_numbers(loaded.study, "study")
        if isinstance(loaded.study, AlphaStudy):
            check_alpha_study(loaded.study, loaded.scenario, resolved.start.size)
        if isinstance(loaded.study, MethodComparison):
            check_method_comparison(loaded.study, loaded.scenario)
    except ScenarioError as error:
        raise ScenarioError(f"{origin}: {error}") from None
    return LoadedScenarioFile(path=path, scenario=loaded.scenario, study=loaded.study,
                              resolved=resolved)


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
    if scenario.demonstration is None:
        raise ScenarioError("the alpha study needs scenario.demonstration")
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
    if not (np.isfinite(study.goal_tolerance) and study.goal_tolerance > 0):
        raise ScenarioError(f"study.goal_tolerance must be positive, got {study.goal_tolerance}")
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


def check_method_comparison(study, scenario):
    """The method comparison's methods, trials and seeds, for `scenario` (a person's
    operator is refused by `pbp-drake study`, not here: `run` takes the file with one)."""
    if not isinstance(scenario.robot, TASK_ROBOTS):
        raise ScenarioError("study !MethodComparison runs the tasks: use robot: !Hsr or "
                            "!Arm")
    if not study.methods:
        raise ScenarioError("study.methods is empty")
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


def _load_error_message(error):
    """A root that is not a mapping, said plainly; everything else names its field by
    `describe_load_error`."""
    root = re.match(r"YAML root was a <class '(\w+)'>", str(error))
    if root:
        found = {"NoneType": "nothing", "str": "a string", "list": "a list", "int": "a number",
                 "float": "a number", "bool": "true or false"}.get(root[1], root[1])
        return (f"the file's top level holds {found}; expected a mapping with `scenario:` "
                "(and optionally `study:`)")
    return describe_load_error(error)
