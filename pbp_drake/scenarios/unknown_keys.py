"""Which mapping of a scenario file holds a key its schema does not know.

Drake's loader says only "The fields ['beta'] were unknown to the schema", not where; a
suggestion drawn from every field name of every section then proposed keys of other
sections (or the unknown key itself, when another section has it). `unknown_key_message`
walks the file next to its schema and names the mapping, its real keys and the closest.
"""

import dataclasses
import difflib
import types
import typing

from pydrake.common.yaml import yaml_load


def unknown_key_message(text, schema):
    """`field.path: unknown key 'k' ...` for the first unknown key of the YAML `text` read
    as `schema`, or None when there is none (or the text cannot be walked)."""
    try:
        data = yaml_load(data=text, private=True)
    except Exception:  # noqa: BLE001 - Drake's loader has already reported what it could
        return None
    found = _first_unknown(data, schema, "")
    if found is None:
        return None
    field, key, known = found
    where = field or "the file's top level"
    matches = difflib.get_close_matches(key, [name for name in known if name != key], n=1)
    suggestion = f" (did you mean {matches[0]!r}?)" if matches else ""
    return (f"{where}: unknown key {key!r}{suggestion}; expected one of "
            f"{', '.join(sorted(known))}")


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


def _variant(schema, node):
    """The schema a node is read as: a Union's member chosen by the node's tag (the first
    member when untagged, as Drake's loader does), an Optional's inner type."""
    if typing.get_origin(schema) not in (typing.Union, types.UnionType):
        return schema
    members = [member for member in typing.get_args(schema) if member is not type(None)]
    tag = node.get("_tag", "").lstrip("!") if isinstance(node, dict) else ""
    for member in members:
        if tag and getattr(member, "__name__", "") == tag:
            return member
    return members[0] if members and not tag else None


def _first_unknown(node, schema, field):
    schema = _variant(schema, node)
    if schema is None:
        return None
    if isinstance(node, list):
        args = typing.get_args(schema)
        if typing.get_origin(schema) is not list or not args:
            return None
        for index, item in enumerate(node):
            found = _first_unknown(item, args[0], f"{field}[{index}]")
            if found:
                return found
        return None
    types_of = _field_types(schema)
    if not isinstance(node, dict) or types_of is None:
        return None
    for key, value in node.items():
        if key == "_tag":
            continue
        if key not in types_of:
            return field, key, list(types_of)
        found = _first_unknown(value, types_of[key], f"{field}.{key}" if field else key)
        if found:
            return found
    return None
