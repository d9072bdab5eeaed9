"""Scenario fields changed on the command line, as Drake's `examples/hardware_sim` changes
them: `--set FIELD=VALUE` (a dotted path, e.g. `goal_estimator.method=nearest`, the value
read as YAML) and `--scenario-text YAML` (a mapping of fields merged onto the file).

Paths and the text's keys are the fields under the file's `scenario:`, or with `study.` of
its `study:`. The overrides are merged onto the file's parsed YAML document before it is
read into the schema, so they are checked exactly as the file is.
"""

import dataclasses
import shlex

import yaml

from pbp_drake.scenarios.bounds import check_yaml_bounds, load_document
from pbp_drake.scenarios.schema import ScenarioError

# The file's sections: a path starting with `study.` is in the second, any other in the first.
SCENARIO, STUDY = "scenario", "study"


@dataclasses.dataclass(frozen=True)
class ScenarioOverrides:
    """The command line's changes to a scenario file: `settings` (`FIELD=VALUE`, applied
    in order) after `text` (a YAML mapping, or None). `typed` says how each setting was
    typed, for messages (e.g. `--operator virtual`; empty: `--set FIELD=VALUE` each)."""

    settings: tuple[str, ...] = ()
    text: str | None = None
    typed: tuple[str, ...] = ()

    def __post_init__(self):
        self.overlay()  # a bad setting or text is refused when the command line is read

    def __bool__(self):
        return bool(self.settings) or self.text is not None

    def words(self):
        """The overrides as typed: `--scenario-text '...' --operator virtual --set A=B ...`."""
        words = [] if self.text is None else [shlex.join(["--scenario-text", self.text])]
        for index, setting in enumerate(self.settings):
            words.append(self.typed[index] if index < len(self.typed)
                         else shlex.join(["--set", setting]))
        return " ".join(dict.fromkeys(words))  # a flag typed once, for two settings

    def record(self):
        """The overrides as `study.json` records them."""
        return {"set": list(self.settings), "scenario_text": self.text}

    def overlay(self):
        """The overrides as one YAML document of the file's shape ({"scenario": ...,
        "study": ...}), to merge onto the file's (`merged`)."""
        overlay = {}
        if self.text is not None:
            overlay = _file_shaped(_text_overlay(self.text))
        for setting in self.settings:
            path, value = parse_setting(setting)
            if path[0] != STUDY:
                path = [SCENARIO, *path]
            nested = value
            for name in reversed(path):
                nested = {name: nested}
            overlay = merged(overlay, nested)
        return overlay


def parse_setting(setting):
    """`FIELD.PATH=VALUE` as (["FIELD", "PATH"], value): the value read as YAML, so that
    `0.02` is a number, `[5, 5]` a list and `!Keyboard {}` an operator."""
    path, equals, value = setting.partition("=")
    names = path.strip().split(".")
    if not equals or not all(name.strip() for name in names):
        raise ScenarioError(f"--set {setting!r}: expected FIELD=VALUE, FIELD a dotted path "
                            "of the scenario's fields (e.g. goal_estimator.method=nearest)")
    try:
        value = load_document(value) if value.strip() else None
    except yaml.YAMLError as error:
        raise ScenarioError(f"--set {setting}: the value is not YAML "
                            f"({_one_line(error)})") from None
    return [name.strip() for name in names], value


def merged(base, overlay):
    """`overlay` merged onto `base` (YAML documents as `bounds.load_document` reads them):
    mappings key by key, anything else replaced. A tagged mapping of another tag (another
    operator, robot or task) replaces the base's; one without a tag keeps the base's."""
    if not isinstance(base, dict) or not isinstance(overlay, dict):
        return overlay
    if "_tag" in overlay and overlay["_tag"] != base.get("_tag"):
        return overlay
    result = dict(base)
    for key, value in overlay.items():
        result[key] = merged(base[key], value) if key in base else value
    return result


def _text_overlay(text):
    """`--scenario-text`'s mapping, its aliases bounded as a file's are."""
    try:
        check_yaml_bounds(text)
        overlay = load_document(text)
    except ScenarioError as error:
        raise ScenarioError(f"--scenario-text: {error}") from None
    except yaml.YAMLError as error:
        raise ScenarioError(f"--scenario-text: not YAML ({_one_line(error)})") from None
    if not isinstance(overlay, dict):
        raise ScenarioError("--scenario-text: expected a mapping of the scenario's fields, "
                            "e.g. '{control_period: 0.02, goal_estimator: {method: nearest}}'")
    return overlay


def _file_shaped(overlay):
    """A mapping of scenario fields (and `study`) as the file's document."""
    shaped = {SCENARIO: {key: value for key, value in overlay.items() if key != STUDY}}
    if STUDY in overlay:
        shaped[STUDY] = overlay[STUDY]
    return shaped


def _one_line(error):
    return " ".join(str(error).split())
