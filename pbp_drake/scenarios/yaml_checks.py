"""Checks of a scenario file's text before and around Drake's YAML loader, so that every
broken file ends in a message that names the file and the line or the field.

`read_scenario_text` refuses binary and non-UTF-8 files, tabs in the indentation and
duplicate keys (YAML's loader silently keeps the last of two equal keys);
`describe_load_error` turns what `yaml_load_typed` raises (a syntax error, a value of the
wrong type, an empty section) into `line L, column C: ...` or `field.path: ...`.
"""

import dataclasses
import re
import typing

from pbp_drake.scenarios.schema import ScenarioError

_BLOCK_KEY = re.compile(r"^( *)((?:- +)*)([A-Za-z_][\w.-]*|\"[^\"]*\"|'[^']*') *:(?: |$)")
_MERGE_FRAME = "_merge_yaml_dict_item_into_target"


def read_scenario_text(path):
    """The file's text; raises ScenarioError (without the file's name) for a binary or
    non-UTF-8 file, a tab in the indentation or a duplicate key."""
    data = path.read_bytes()
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
    check_duplicate_keys(text)
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
