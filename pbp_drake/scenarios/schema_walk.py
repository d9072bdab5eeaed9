"""The file's mappings walked next to its schema, for what Drake's loader misreports.

Drake's loader says only "The fields ['beta'] were unknown to the schema", not where (a
suggestion drawn from every field name of every section then proposed keys of other
sections, or the unknown key itself); and a number or a word where a tagged section
belongs (`demonstration: 3`, `robot: 3`, `study: fast`) it pours into some field of the
first variant, to fail later with a TypeError or not at all. `shape_problem` names the
mapping and says what belongs there.
"""

import dataclasses
import difflib
import types
import typing

from pydrake.common.yaml import yaml_load


def shape_problem(text, schema):
    """`field.path: what is wrong; expected ...` for the first unknown key, or value that
    is not a mapping where the schema has one, of the YAML `text` read as `schema`; None
    when there is none (or the text does not parse: the loader reports that)."""
    try:
        data = yaml_load(data=text, private=True)
    except Exception:  # noqa: BLE001 - Drake's loader reports what does not parse
        return None
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


def _first_problem(node, schema, field):
    optional = type(None) in typing.get_args(schema)
    variant = _variant(schema, node)
    if variant is None or (node is None and optional):
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
