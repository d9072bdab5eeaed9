"""What a scenario file may hold, and its YAML read within those bounds.

Drake's `yaml_load_typed` parses with PyYAML's pure-Python loader (about 5 s a megabyte)
and follows every alias as it copies values into the dataclasses, so ten megabytes of goals
or a few lines of nested aliases (a "billion laughs") cost minutes and gigabytes before any
check can run. A scenario file is read here in bounded steps instead: its bytes
(`read_bounded`); its YAML events, from libyaml where PyYAML has it, counted before any
value is made (`check_yaml_bounds`); its document, made once by the same loader with
Drake's reading of tags (`load_document`), then copied into the schema by Drake's typed
loader (`load_typed`).
"""

import pathlib

import yaml
from pydrake.common import yaml as drake_yaml
from pydrake.common.yaml import yaml_load_typed
from yaml.events import (
    AliasEvent, MappingEndEvent, MappingStartEvent, ScalarEvent, SequenceEndEvent,
    SequenceStartEvent)

from pbp_drake.scenarios.schema import ScenarioError

#: The largest scenario file read (bytes): the shipped files are near 3 KB; 10,000 goals of
#: three coordinates written at full precision (as `yaml_dump` writes them) take about
#: 550 KB.
MOST_FILE_BYTES = 1 << 20
#: The most values (numbers, strings, lists, mappings) a file's aliases may repeat, each
#: alias counted with everything it stands for: a few blocks used twice are hundreds; a
#: billion-laughs file of 86 KB repeats billions.
MOST_ALIASED_VALUES = 100_000
#: The most candidate goals (one DMP each) a scenario holds, in `scenario.goals` or a
#: reaching task's `objects` (`run --goals` too): `pbp-drake bench` steps the DMP bank up to
#: 100,000 goals, and the loop runs live with 10,000 (docs/performance.md).
#: Not below MOST_ALIASED_VALUES: an alias of more goals repeats more values, refused as such.
MAX_GOALS = 100_000
#: The lists of goals a scenario file may hold, by field, with the word for one goal.
GOAL_LISTS = {"scenario.goals": "goals", "scenario.task.objects": "objects"}

# PyYAML's C loader where PyYAML was built with libyaml, else its Python one.
_BASE_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def is_special_file(path):
    """Whether `path` names a device, a pipe or a socket, which is never read: a device
    such as /dev/zero never ends, and a pipe's open waits for a writer."""
    path = pathlib.Path(path)
    return path.exists() and not (path.is_file() or path.is_dir())


def read_bounded(path):
    """The bytes of the file at `path`; raises ScenarioError (without the file's name) when it
    holds more than MOST_FILE_BYTES, having read no more than that."""
    with open(path, "rb") as file:
        data = file.read(MOST_FILE_BYTES + 1)
    if len(data) > MOST_FILE_BYTES:
        size = path.stat().st_size
        held = f"{size:,} bytes" if size > MOST_FILE_BYTES else "more than that"
        raise ScenarioError(f"the file holds {held}; a scenario file is at most "
                            f"{MOST_FILE_BYTES:,} bytes (1 MiB)")
    return data


def goal_count_problem(field, count, line=None):
    """The words of a ScenarioError for `count` goals in the list `field` (of GOAL_LISTS),
    None when within MAX_GOALS; `line` when the count is known only to exceed it."""
    if count <= MAX_GOALS:
        return None
    where = f", line {line}," if line is not None else ""
    held = f"more than {MAX_GOALS:,}" if line is not None else f"{count:,}"
    return (f"{field}{where} holds {held} {GOAL_LISTS[field]}; a scenario has at most "
            f"{MAX_GOALS:,} candidate goals")


def check_goal_counts(scenario):
    """Raises ScenarioError when a 2-D scene's `goals` or a robot task's `objects` hold
    more than MAX_GOALS goals."""
    task = getattr(scenario, "task", None)
    for field, goals in (("scenario.goals", getattr(scenario, "goals", ())),
                         ("scenario.task.objects", getattr(task, "objects", ()))):
        problem = goal_count_problem(field, len(goals))
        if problem:
            raise ScenarioError(problem)


class _OpenNode:
    """A sequence or mapping whose events are being read."""

    __slots__ = ("field", "anchor", "mapping", "goals", "values", "items", "key", "expect_key")

    def __init__(self, field, event):
        self.field = field
        self.anchor = event.anchor
        self.mapping = isinstance(event, MappingStartEvent)
        self.goals = field in GOAL_LISTS
        self.values = 1  # itself and, as they end, everything in it (aliases expanded)
        self.items = 0
        self.key = None
        self.expect_key = True

    def add(self, event, values):
        """Counts a node of `values` values that `event` starts in this one; returns the
        new node's field (`scenario.task.objects`, `scenario.goals[3]`), None for a
        mapping's key or in one."""
        self.values += values
        if self.mapping:
            self.expect_key = not self.expect_key
            if not self.expect_key:
                self.key = event.value if type(event) is ScalarEvent else None
                return None
            if self.field is None or self.key is None:
                return None
            return f"{self.field}.{self.key}" if self.field else str(self.key)
        self.items += 1
        if self.goals and self.items > MAX_GOALS:
            raise ScenarioError(goal_count_problem(self.field, self.items,
                                                   event.start_mark.line + 1))
        return None if self.field is None else f"{self.field}[{self.items - 1}]"


class _Document(_OpenNode):
    """What holds the document's root node (of field ``)."""

    def add(self, event, values):
        self.values += values
        return ""


def check_yaml_bounds(text):
    """Raises ScenarioError (`field, line L: ...`) when the YAML `text` repeats more than
    MOST_ALIASED_VALUES values by its aliases, has an alias inside the node it names, or
    holds more than MAX_GOALS goals in a list of GOAL_LISTS. Reads the events only; a text
    that does not parse is left to the loader, which says where."""
    anchored = {}  # anchor: values of the node it names, once that node has ended
    open_nodes = [_Document(None, SequenceStartEvent(None, None, True))]
    aliased = 0
    loader = _BASE_LOADER(text)
    try:
        while loader.check_event():
            event = loader.get_event()
            kind = type(event)
            if kind is ScalarEvent:  # most events: kept short
                open_nodes[-1].add(event, 1)
                if event.anchor is not None:
                    anchored[event.anchor] = 1
            elif kind in (SequenceStartEvent, MappingStartEvent):
                open_nodes.append(_OpenNode(open_nodes[-1].add(event, 0), event))
            elif kind in (SequenceEndEvent, MappingEndEvent):
                node = open_nodes.pop()
                open_nodes[-1].values += node.values
                if node.anchor is not None:
                    anchored[node.anchor] = node.values
            elif kind is AliasEvent:
                values = anchored.get(event.anchor, 0)
                field = open_nodes[-1].add(event, values)
                if event.anchor not in anchored:
                    _check_alias_target(event, open_nodes, field)
                    continue  # undefined: the loader says so
                aliased += values
                if aliased > MOST_ALIASED_VALUES:
                    raise ScenarioError(
                        f"{field or 'the file'}, line {event.start_mark.line + 1}: the "
                        f"file's aliases repeat more than {MOST_ALIASED_VALUES:,} values "
                        f"(*{event.anchor} here repeats {values:,}); a scenario file's "
                        f"aliases may repeat at most {MOST_ALIASED_VALUES:,}")
    except yaml.YAMLError:
        return
    finally:
        loader.dispose()


def _check_alias_target(event, open_nodes, field):
    """An alias to a node not yet ended: one it is inside of (a cycle) is refused."""
    if any(node.anchor == event.anchor for node in open_nodes):
        raise ScenarioError(f"{field or 'the file'}, line {event.start_mark.line + 1}: the "
                            f"alias *{event.anchor} stands inside the node it names (a "
                            "cycle); a scenario file's aliases name nodes that end before "
                            "them")


class _TaggedLoader(_BASE_LOADER):
    """Drake's reading of YAML (`pydrake.common.yaml.yaml_load_data`: a tagged node is its
    mapping with the tag as a `_tag` key) on PyYAML's C loader, refusing a key given twice
    in one mapping (PyYAML keeps the last)."""

    def construct_mapping(self, node, deep=False):
        first_lines = {}
        for key_node, _ in node.value if isinstance(node, yaml.MappingNode) else ():
            if key_node.tag == "tag:yaml.org,2002:merge" or not isinstance(key_node.value, str):
                continue
            line = key_node.start_mark.line + 1
            if key_node.value in first_lines:
                raise ScenarioError(
                    f"line {line}: duplicate key {key_node.value!r} (first on line "
                    f"{first_lines[key_node.value]}); each key may appear once in a mapping")
            first_lines[key_node.value] = line
        return super().construct_mapping(node, deep)


def _tagged_mapping(loader, tag, node):
    result = loader.construct_mapping(node)
    result["_tag"] = tag
    return result


_TaggedLoader.add_multi_constructor("", _tagged_mapping)


def load_document(text):
    """The YAML `text` as Drake's loader reads it, root keys starting with `_` kept; raises
    ScenarioError for a key given twice in a mapping, what PyYAML raises for text that
    does not parse."""
    return yaml.load(text, Loader=_TaggedLoader)


class _TaggedDumper(yaml.SafeDumper):
    """Writes a document of `load_document` back as YAML, its `_tag` keys as tags."""


def _tagged_representation(dumper, data):
    items = {key: value for key, value in data.items() if key != "_tag"}
    return dumper.represent_mapping(data.get("_tag", "tag:yaml.org,2002:map"), items)


_TaggedDumper.add_representer(dict, _tagged_representation)


def load_typed(schema, document):
    """`schema` read from `document` (of `load_document`) by Drake's typed loader, as
    `yaml_load_typed(schema=schema, data=...)` reads its text but without parsing it again
    (by `yaml_load_typed` itself where this Drake lacks the pieces it is made of)."""
    merge = getattr(drake_yaml, "_merge_yaml_dict_into_target", None)
    options = getattr(drake_yaml, "_LoadYamlOptions", None)
    if merge is None or options is None:
        return yaml_load_typed(schema=schema, data=yaml.dump(document, Dumper=_TaggedDumper))
    # As yaml_load_typed: root keys starting with `_` are private (anchors' templates).
    document = {key: value for key, value in document.items()
                if not (isinstance(key, str) and key.startswith("_"))}
    result = schema()
    merge(options=options(allow_yaml_with_no_schema=False, allow_schema_with_no_yaml=True,
                          retain_map_defaults=True),
          yaml_dict=document, target=result, target_schema=schema)
    return result
