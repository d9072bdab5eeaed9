"""Our Sphinx directives: each page part that would drift from the code is generated from it.

- `pydrake_system`: Drake's port block of a LeafSystem docstring, drawn as a box;
- `cli-reference`: every `pbp-drake` subcommand from its argparse parser, and the exit codes;
- `scenario-reference`: every field reachable from `ScenarioFile` and `TaskScenario`, from the
  dataclasses and their `#:` doc comments;
- `api-reference`: a table of every name of `pbp_drake.__all__` (its topic from
  `pbp_drake.API_GROUPS`), each name's own page generated under `reference/api/`.
"""

import argparse
import dataclasses
import inspect
import pathlib
import typing

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.pycode import ModuleAnalyzer
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import nested_parse_with_titles


def _parse_rst(directive, lines):
    """Parses generated reST lines into nodes (so titles and autodoc directives work)."""
    node = nodes.container()
    nested_parse_with_titles(directive.state, StringList(lines, "<generated>"), node)
    return node.children


# --- pydrake_system -------------------------------------------------------------------------

def port_diagram(name, inputs, outputs):
    """A box named `name` with the input ports on its left and the outputs on its right."""
    rows = max(len(inputs), len(outputs), 1)
    inputs = inputs + [""] * (rows - len(inputs))
    outputs = outputs + [""] * (rows - len(outputs))
    width = max(len(name), 6) + 4
    left = max((len(port) for port in inputs), default=0)
    lines = [" " * (left + 4) + "┌" + "─" * width + "┐",
             " " * (left + 4) + "│" + name.center(width) + "│"]
    for port_in, port_out in zip(inputs, outputs):
        arrow_in = f"{port_in:>{left}} ──▶" if port_in else " " * (left + 4)
        arrow_out = f"──▶ {port_out}" if port_out else ""
        lines.append(f"{arrow_in}│{' ' * width}│{arrow_out}")
    lines.append(" " * (left + 4) + "└" + "─" * width + "┘")
    return "\n".join(line.rstrip() for line in lines)


class PydrakeSystem(SphinxDirective):
    """`.. pydrake_system::` with a YAML-like body: name, input_ports, output_ports."""

    has_content = True

    def run(self):
        fields, key = {"name": "", "input_ports": [], "output_ports": []}, None
        for line in self.content:
            text = line.strip()
            if text.startswith("- ") and key:
                fields[key].append(text[2:].strip())
            elif ":" in text:
                key, value = (part.strip() for part in text.split(":", 1))
                if key == "name":
                    fields["name"] = value
        diagram = port_diagram(fields["name"], fields["input_ports"], fields["output_ports"])
        block = nodes.literal_block(diagram, diagram, classes=["pydrake-system"])
        return [block]


# --- cli-reference --------------------------------------------------------------------------

def _option_lines(parser):
    lines = []
    for action in parser._actions:
        if (isinstance(action, (argparse._HelpAction, argparse._SubParsersAction))
                or action.help == argparse.SUPPRESS):  # an alias kept out of the help
            continue
        name = ", ".join(action.option_strings) or action.metavar or action.dest
        facts = []
        if action.choices:
            facts.append("choices: " + ", ".join(f"``{choice}``" for choice in action.choices))
        if (action.option_strings and action.default not in (None, False, argparse.SUPPRESS)
                and not isinstance(action, argparse._VersionAction)):
            facts.append(f"default: ``{action.default}``")
        help_text = (action.help or "").replace("%(prog)s", parser.prog)
        help_text = help_text.replace("*", r"\*").replace("`", "``").replace("````", "``")
        help_text = help_text or "(no help text)"
        lines += [f"``{name}``", f"   {help_text}" + (f" ({'; '.join(facts)})" if facts else ""),
                  ""]
    return lines


def _command_lines(prog, parser, underline="-"):
    # argparse indents the usage's later lines under "usage: ", which the page leaves out.
    usage = "\n".join(line.removeprefix("usage: ").removeprefix(" " * len("usage: "))
                      for line in parser.format_usage().strip().splitlines())
    lines = [prog, underline * len(prog), "", (parser.description or "").replace("`", "``"), "",
             ".. code-block:: text", "", *("   " + line for line in usage.splitlines()), ""]
    return lines + _option_lines(parser)


class CliReference(SphinxDirective):
    """The whole `pbp-drake` command line, from `pbp_drake.cli.build_parser()`."""

    def run(self):
        from pbp_drake import cli

        parser, tools = cli.build_parser(), cli.tool_parsers()
        lines = _command_lines("pbp-drake", parser)
        subparsers = next(action for action in parser._actions
                          if isinstance(action, argparse._SubParsersAction))
        for name, subparser in subparsers.choices.items():
            # bench and draw parse their own line: document their own parsers.
            lines += _command_lines(f"pbp-drake {name}", tools.get(name, subparser))
        return _parse_rst(self, lines + _exit_code_lines())


def _exit_code_lines():
    """The exit codes, from `pbp_drake.cli_types.EXIT_CODES`."""
    from pbp_drake.cli_types import EXIT_CODES

    lines = ["Exit codes", "----------", ""]
    for code, meaning in EXIT_CODES.items():
        lines += [f"``{code}``", f"   {meaning.replace('`', '``').replace('````', '``')}", ""]
    return lines


# --- scenario-reference ---------------------------------------------------------------------

def field_docs(cls):
    """{field name: its `#:` doc comment} of a dataclass, its bases' included."""
    docs = {}
    for base in reversed(cls.__mro__):
        if not dataclasses.is_dataclass(base):
            continue
        analyzer = ModuleAnalyzer.for_module(base.__module__)
        for (scope, name), lines in analyzer.find_attr_docs().items():
            if scope == base.__qualname__:
                docs[name] = " ".join(line.strip() for line in lines).strip()
    return docs


def _variants(annotation):
    """The dataclasses a field's type names (through Optional, Union and list)."""
    if dataclasses.is_dataclass(annotation):
        return [annotation]
    return [cls for arg in typing.get_args(annotation) for cls in _variants(arg)]


def _is_ours(cls):
    return cls.__module__.startswith("pbp_drake")


def reachable_dataclasses(*roots):
    """Our dataclasses reachable from `roots`, in order of first appearance."""
    seen, order = set(), []

    def visit(cls):
        if cls in seen or not _is_ours(cls):
            return
        seen.add(cls)
        order.append(cls)
        for field in dataclasses.fields(cls):
            for variant in _variants(typing.get_type_hints(cls)[field.name]):
                visit(variant)

    for root in roots:
        visit(root)
    return order


def _type_name(annotation):
    if isinstance(annotation, type) and not typing.get_args(annotation):
        return annotation.__name__
    text = str(annotation).replace("typing.", "")
    for prefix in ("pbp_drake.", "pydrake."):
        while prefix in text:  # module paths out: the class names are what a reader writes
            start = text.index(prefix)
            end = start
            while end < len(text) and (text[end].isalnum() or text[end] in "._"):
                end += 1
            text = text[:start] + text[start:end].rsplit(".", 1)[-1] + text[end:]
    return text


def _default(field):
    if field.default is not dataclasses.MISSING:
        value = field.default
    elif field.default_factory is not dataclasses.MISSING:
        value = field.default_factory()
    else:
        return "required"
    if dataclasses.is_dataclass(value):
        return f"{type(value).__name__} defaults"
    if type(value).__module__.startswith("pydrake"):
        return f"Drake's {type(value).__name__} defaults"
    return repr(value)


def _tag_note(cls, annotation_users):
    users = annotation_users.get(cls, [])
    untagged = [f"``{field}: {{...}}``" for field, first in users if first]
    tagged = [f"``{field}: !{cls.__name__} {{...}}``" for field, first in users if not first]
    return ", ".join(tagged + untagged)


class ScenarioReference(SphinxDirective):
    """Every section a scenario file may hold, generated from `ScenarioFile`."""

    def run(self):
        from pbp_drake.scenarios.schema import ScenarioFile, TaskScenario

        # A file's scenario is a 2-D scene's or, by its robot's tag, a robot task's.
        classes = reachable_dataclasses(ScenarioFile, TaskScenario)
        # Where each class appears and whether it is the field's untagged (first) variant.
        users = {TaskScenario: [("scenario", True)]}
        for cls in classes:
            for field in dataclasses.fields(cls):
                variants = [v for v in _variants(typing.get_type_hints(cls)[field.name])]
                for index, variant in enumerate(variants):
                    users.setdefault(variant, []).append((field.name, index == 0))
        lines = []
        for cls in classes:
            lines += [cls.__name__, "-" * len(cls.__name__), ""]
            note = _tag_note(cls, users)
            if note:
                lines += [f"Written as {note}.", ""]
            doc = inspect.getdoc(cls) or ""
            lines += [line.replace("`", "``").replace("````", "``") for line in doc.splitlines()]
            lines.append("")
            docs, hints = field_docs(cls), typing.get_type_hints(cls)
            for field in dataclasses.fields(cls):
                lines += [f"``{field.name}``",
                          f"   *{_type_name(hints[field.name])}*, default ``{_default(field)}``."
                          f" {docs.get(field.name, '(not described)')}", ""]
        return _parse_rst(self, [line.replace("\u00a0", " ") for line in lines])


# --- api-reference --------------------------------------------------------------------------

# The folder, under the source folder, of the one page per public name (written at each
# build by `_write_api_pages`, not kept in git).
API_FOLDER = "reference/api"


def api_groups():
    """{topic: [public name, ...]} of `pbp_drake.API_GROUPS`, any name it misses under
    "Other"."""
    import pbp_drake

    groups = {title: list(names) for title, names in pbp_drake.API_GROUPS.items()}
    grouped = {name for names in groups.values() for name in names}
    other = [name for name in pbp_drake.__all__ if name not in grouped and name != "__version__"]
    if other:
        groups["Other"] = other
    return groups


def summary(value):
    """The first sentence of `value`'s docstring, on one line ("" without one)."""
    paragraph = " ".join((inspect.getdoc(value) or "").split("\n\n", 1)[0].split())
    at = 0
    while True:
        at = paragraph.find(". ", at) + 1
        if at == 0:
            return paragraph
        before = paragraph[:at]
        # Not inside `code`, nor an abbreviation.
        if before.count("`") % 2 == 0 and not before.endswith(("e.g.", "i.e.", "vs.")):
            return before


def _api_page(name, topic):
    import pbp_drake

    value = getattr(pbp_drake, name)
    if inspect.ismodule(value):
        directive = [f".. automodule:: {value.__name__}", "   :members:"]
    elif inspect.isclass(value):
        directive = [f".. autoclass:: pbp_drake.{name}", "   :members:"]
        # Members a class inherits from one of ours (`Dmp.rollout` from `SingleDmp`) are
        # its own to a reader; Drake's and Python's (LeafSystem's, tuple's) are not.
        foreign = [base.__name__ for base in value.__mro__[1:]
                   if not base.__module__.startswith("pbp_drake")]
        if len(foreign) < len(value.__mro__) - 1:
            directive.append(f"   :inherited-members: {', '.join(foreign)}")
    else:
        directive = [f".. autofunction:: pbp_drake.{name}"]
    # Orphans, reached from the table: in a toctree, each of them would stand in every page's
    # sidebar (furo's navigation tree, rebuilt for every page, took half the build).
    return "\n".join([":orphan:", "", name, "=" * len(name), "",
                      f"*{topic}* (:doc:`every public name <../api>`)", "", *directive, ""])


def _write_api_pages(app):
    """One page per public name under `API_FOLDER`, rewritten only when it changes."""
    folder = pathlib.Path(app.srcdir) / API_FOLDER
    folder.mkdir(exist_ok=True)
    pages = {f"{name}.rst": _api_page(name, topic)
             for topic, names in api_groups().items() for name in names}
    for stale in folder.glob("*.rst"):
        if stale.name not in pages:
            stale.unlink()
    for file_name, text in pages.items():
        path = folder / file_name
        if not path.exists() or path.read_text() != text:
            path.write_text(text)


class ApiReference(SphinxDirective):
    """Every public name, one section per topic of `pbp_drake.API_GROUPS`: a table of each
    name (a link to its page, an orphan: no sidebar lists them) and its docstring's first
    sentence."""

    def run(self):
        import pbp_drake

        folder = API_FOLDER.rsplit("/", 1)[1]
        lines = []
        for topic, names in api_groups().items():
            lines += [topic, "-" * len(topic), "", ".. list-table::", "   :widths: 30 70", ""]
            for name in names:
                lines += [f"   * - :doc:`{name} <{folder}/{name}>`",
                          f"     - {summary(getattr(pbp_drake, name)) or ' '}"]
            lines.append("")
        return _parse_rst(self, lines)


# The pages generated from the code: re-read at every build, since Sphinx sees only
# their Markdown (unchanged) and would keep an old page after the code changed.
GENERATED_PAGES = ["reference/cli", "reference/scenario-files", "reference/api"]


def _generated_pages(app, env, added, changed, removed):
    return [page for page in env.found_docs
            if page in GENERATED_PAGES or page.startswith(API_FOLDER + "/")]


def setup(app):
    app.connect("builder-inited", _write_api_pages)
    app.connect("env-get-outdated", _generated_pages)
    app.add_directive("pydrake_system", PydrakeSystem)
    app.add_directive("cli-reference", CliReference)
    app.add_directive("scenario-reference", ScenarioReference)
    app.add_directive("api-reference", ApiReference)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
