"""The checks of an arm's model file (URDF or SDFormat) before Drake reads it, over the
file's XML alone: what would hang, fail at build or mid-run, or print unreadable names
(the list: docs/concepts/your-robot.md, "What is checked in the model file"). Each refusal
is a one-line ValueError naming the config's field, the file and the element.
"""

import dataclasses
import math
import re
import unicodedata
import xml.parsers.expat
from pathlib import Path

import numpy as np
from pydrake.multibody.parsing import PackageMap

from pbp_drake.robots.hsr_model import PACKAGE_NAME, models_dir

# Our arm's file is 20 KB, and a robot of a few hundred links well under 1 MB. The checks
# are pure Python: a file of 2 MB (8,000 links) takes them 1.7 s on a loaded machine, the
# most the 2 s they are promised in leaves.
MAX_MODEL_FILE_BYTES = 2_000_000
# Drake downloads this package's files on first use: a model that needs it needs the
# network, which a run must not.
NETWORK_PACKAGES = ("drake_models",)
# Unicode categories no name needs: control characters (NUL, newline, escape), invisible
# formatting (the right-to-left override, zero-width joiners) and line/paragraph breaks.
FORBIDDEN_NAME_CATEGORIES = ("Cc", "Cf", "Zl", "Zp")
# Characters XML 1.0 does not allow (a parser stops at them) are read as these private-use
# stand-ins, so that the name holding one can be named (`_readable_xml`).
_STAND_IN = 0x10FF00
_STAND_INS = re.compile("[\U0010ff00-\U0010ff1f]")
# A name of printable ASCII needs no closer look.
_PLAIN_NAME = re.compile(r"[ -~]*")
# Joint types that move nothing (URDF and SDFormat spell them alike).
FIXED_JOINT_TYPES = ("fixed",)
# The tolerance (relative to the largest moment) of the inertia checks: the values are
# printed to a few digits in most files.
INERTIA_TOLERANCE = 1e-6


def printable(name):
    """`name` quoted with every character a terminal would act on escaped (repr-like)."""
    return repr(original_text(name))


def escaped(text):
    """`text` unquoted, with each character a terminal would act on escaped as in `repr`
    (for messages that quote what another reader, Drake's, says about the file)."""
    return "".join(char if char.isprintable() else repr(char)[1:-1]
                   for char in original_text(text))


def original_text(text):
    """`text` read from the file with the stand-ins of `_readable_xml` turned back into the
    characters the file holds."""
    if not _STAND_INS.search(text):
        return text
    return "".join(chr(ord(c) - _STAND_IN) if _STAND_IN <= ord(c) < _STAND_IN + 0x20 else c
                   for c in text)


class XmlElement:
    """One element of the file: its tag, attributes, text, children and line."""

    __slots__ = ("tag", "attrib", "line", "children", "text")

    def __init__(self, tag, attrib, line):
        self.tag, self.attrib, self.line, self.children, self.text = tag, attrib, line, [], ""

    def find_all(self, tag):
        return [child for child in self.children if child.tag == tag]

    def find(self, tag):
        return next((child for child in self.children if child.tag == tag), None)

    def walk(self):
        """This element and all below it, in document order (no recursion: a file may
        nest deeper than Python's stack)."""
        stack = [self]
        while stack:
            element = stack.pop()
            yield element
            stack.extend(reversed(element.children))


@dataclasses.dataclass
class ModelFile:
    """A checked model file: its `path`, `kind` ("urdf" or "sdf") and XML `root` (the
    `<robot>`, or SDFormat's first `<model>`)."""

    path: Path
    kind: str
    root: XmlElement


class _Refusal:
    """Builds the one-line refusals of one file: `field 'source': line N, what: why`."""

    def __init__(self, field, source):
        self.prefix = f"{field} {printable(source)}"

    def __call__(self, element, what, why):
        line = f"line {element.line}, " if element is not None else ""
        return ValueError(f"{self.prefix}: {line}{what}: {why}")


def _url_path(uri, folder, refuse):
    """The file `uri` names (relative to `folder` unless absolute or a URL); raises what
    `refuse(why)` makes for a URL that needs the network or a package we do not know."""
    scheme, separator, rest = uri.partition("://")
    if not separator:
        path = Path(uri)
        return path if path.is_absolute() else folder / path
    if scheme == "file":
        return Path(rest)
    if scheme not in ("package", "model"):
        raise refuse(f"{printable(uri)} is a URL: reading it needs the network; keep the "
                     "file on disk, next to the model (our models are in models/)")
    package, _separator, inside = rest.partition("/")
    if package in NETWORK_PACKAGES:
        raise refuse(f"{printable(uri)} needs the network (Drake downloads "
                     f"package://{package}); copy the file next to the model and name it "
                     "by a relative path (our models are in models/, "
                     f"package://{PACKAGE_NAME}/...)")
    if package == PACKAGE_NAME:
        return models_dir() / PACKAGE_NAME / inside
    if package == "drake":
        return Path(PackageMap().GetPath("drake")) / inside
    raise refuse(f"{printable(uri)} is in package {printable(package)}, which the station "
                 f"does not know (it knows {PACKAGE_NAME}, ours in models/, and drake); name "
                 "the file by a path relative to the model")


# The files checked last, by (path, modification time, size, motion): a scenario's model is
# checked where it is resolved, where the scene is placed, and where its station is built.
_CHECKED = {}


def check_model_file(source, motion, field="ArmStationConfig.model_file"):
    """Reads and checks the model file `source` (a path from the working folder, or a
    package:// URL of ours or Drake's) for a station of `motion` ("kinematic" or
    "dynamic"); returns its `ModelFile`. Raises a one-line ValueError naming `field`, the
    file, the element and its field."""
    refuse = _Refusal(field, source)
    path = _url_path(source, Path.cwd(), lambda why: refuse(None, "the file", why))
    if not path.is_file():
        raise ValueError(f"{field}: no file at {printable(source)} (a path from the working "
                         "folder, or a package:// URL)")
    status = path.stat()
    size = status.st_size
    key = (str(path.resolve()), status.st_mtime_ns, size, motion)
    if key in _CHECKED:
        return _CHECKED[key]
    if size > MAX_MODEL_FILE_BYTES:
        raise refuse(None, "the file", f"{size:,} bytes is larger than a model file may be "
                     f"({MAX_MODEL_FILE_BYTES:,} bytes)")
    document = _parse(path.read_bytes(), refuse)
    if document.tag == "robot":
        model = ModelFile(path, "urdf", document)
    elif document.tag == "sdf" and document.find("model") is not None:
        model = ModelFile(path, "sdf", document.find("model"))
    else:
        raise refuse(document, f"<{printable(document.tag)[1:-1]}>", "expected a URDF "
                     "<robot> or an SDFormat <sdf><model> as the top element")
    _check_names(document, refuse)
    links, joints = links_and_joints(model)
    _check_tree(links, joints, refuse)
    _check_couplings(model, joints, refuse)
    if model.kind == "urdf":
        _check_urdf_limits(joints, refuse)
    _check_files(document, model, refuse)
    _check_inertias(model, links, joints, motion, refuse)
    if len(_CHECKED) >= 8:
        _CHECKED.pop(next(iter(_CHECKED)))
    _CHECKED[key] = model
    return model


def _parse(data, refuse):
    """The XML tree of `data` with each element's line; ValueError naming the file and
    the line for text that is not UTF-8 XML or declares a DOCTYPE (entities)."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise refuse(None, "the file", f"byte {error.start} is not UTF-8; a model file "
                     "is UTF-8 text") from None
    parser = xml.parsers.expat.ParserCreate()
    parser.buffer_text = True
    stack, roots = [], []

    def start(tag, attrib):
        element = XmlElement(tag, attrib, parser.CurrentLineNumber)
        (stack[-1].children if stack else roots).append(element)
        stack.append(element)

    def end(_tag):
        stack.pop()

    def characters(chunk):
        if stack:
            stack[-1].text += chunk

    def doctype(*_args):
        # Drake's reader expands no entities; a DOCTYPE only serves entity bombs.
        raise ValueError("a DOCTYPE (entity declarations), which a model file has not")

    parser.StartElementHandler, parser.EndElementHandler = start, end
    parser.CharacterDataHandler, parser.StartDoctypeDeclHandler = characters, doctype
    try:
        parser.Parse(_readable_xml(text), True)
    except xml.parsers.expat.ExpatError as error:
        raise ValueError(f"{refuse.prefix} does not load: line {error.lineno}, column "
                         f"{error.offset + 1}: not well-formed XML "
                         f"({xml.parsers.expat.ErrorString(error.code)})") from None
    except ValueError as error:
        raise ValueError(f"{refuse.prefix} does not load: line "
                         f"{parser.CurrentLineNumber}: {error}") from None
    return roots[0]


_CHARACTER_REFERENCE = re.compile(r"&#(x[0-9a-fA-F]+|[0-9]+);")
_FORBIDDEN_IN_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f]")
# Comments, CDATA and processing instructions (left as they are), and start tags, whose
# quoted attribute values may hold `>`.
_MARKUP = re.compile(r"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>"
                     r"|<[^!?/<>\"'][^<>\"']*(?:(?:\"[^\"]*\"|'[^']*')[^<>\"']*)*>", re.DOTALL)
_QUOTED = re.compile(r"\"[^\"]*\"|'[^']*'")
_LINE_BREAKS = re.compile("[\t\n\r]")
# A quoted value holding a raw line break or tab: only then are the tags looked into.
_BROKEN_VALUE = re.compile("=\\s*(?:\"[^\"<]*[\t\n\r][^\"<]*\"|'[^'<]*[\t\n\r][^'<]*')")


def _stand_in(match):
    return chr(_STAND_IN + ord(match.group(0)))


def _readable_xml(text):
    """`text` with the characters XML 1.0 forbids (raw, or as `&#N;`) and raw line breaks
    and tabs inside quoted attribute values (which XML would read as spaces, but Drake's
    reader keeps) as private-use stand-ins, so that the names holding them can be named."""
    def reference(match):
        number = match.group(1)
        value = int(number[1:], 16) if number[0] in "xX" else int(number)
        return chr(_STAND_IN + value) if value < 0x20 and value not in (9, 10, 13) else \
            match.group(0)

    def tag(match):
        markup = match.group(0)
        if markup.startswith(("<!--", "<![CDATA[", "<?")):
            return markup
        return _QUOTED.sub(lambda quoted: _LINE_BREAKS.sub(_stand_in, quoted.group(0)),
                           markup)

    text = _FORBIDDEN_IN_XML.sub(_stand_in, _CHARACTER_REFERENCE.sub(reference, text))
    return _MARKUP.sub(tag, text) if _BROKEN_VALUE.search(text) else text


# Attributes whose value is a name, or names a link (URDF's <parent link>, <child link>).
NAME_ATTRIBUTES = ("name", "link", "joint")
# SDFormat elements whose text names a link or frame.
NAME_ELEMENTS = ("parent", "child", "attached_to")


def _check_names(document, refuse):
    for element in document.walk():
        owner = f"{_describe(element)} " if "name" in element.attrib else ""
        for attribute in NAME_ATTRIBUTES:
            if attribute in element.attrib:
                _check_name(element.attrib[attribute], element,
                            f"{owner}<{element.tag} {attribute}>", refuse)
        if element.tag in NAME_ELEMENTS and element.text.strip():
            _check_name(element.text.strip(), element, f"<{element.tag}>", refuse)


def _check_name(name, element, what, refuse):
    if _PLAIN_NAME.fullmatch(name):
        return
    for char in original_text(name):
        if unicodedata.category(char) in FORBIDDEN_NAME_CATEGORIES:
            kind = ("a control character" if unicodedata.category(char) == "Cc"
                    else "an invisible formatting mark")
            raise refuse(element, what, f"{printable(name)} holds {kind} (U+{ord(char):04X}"
                         f"{', ' + unicodedata.name(char) if unicodedata.name(char, '') else ''}"
                         "); names are printed and typed: use letters, digits, _ and -")


def _describe(element):
    name = element.attrib.get("name")
    return f"{element.tag} {printable(name)}" if name is not None else f"<{element.tag}>"


@dataclasses.dataclass
class _Joint:
    name: str
    kind: str
    parent: str
    child: str
    element: XmlElement


def links_and_joints(model):
    """`({link name: element}, [_Joint])` of the model's top level."""
    links = {link.attrib.get("name", ""): link for link in model.root.find_all("link")}
    joints = []
    for element in model.root.children:
        if element.tag not in ("joint", "drake:joint"):
            continue
        ends = (element.find("parent"), element.find("child"))
        if model.kind == "urdf":
            parent, child = (end.attrib.get("link", "") if end is not None else "" for end in ends)
        else:
            parent, child = (end.text.strip() if end is not None else "" for end in ends)
        joints.append(_Joint(element.attrib.get("name", ""), element.attrib.get("type", ""),
                             parent, child, element))
    return links, joints


def _check_tree(links, joints, refuse):
    """Each link hangs from at most one joint, and no chain of joints comes back to
    where it started (the station walks the chain from the hand to the base)."""
    parent_joint = {}
    for joint in joints:
        if joint.child not in links:
            continue  # a frame or the world: Drake names what it cannot find
        if joint.child in parent_joint:
            first = parent_joint[joint.child]
            raise refuse(joint.element, f"joint {printable(joint.name)} <child>",
                         f"link {printable(joint.child)} already hangs from joint "
                         f"{printable(first.name)} (line {first.element.line}); a link hangs "
                         "from one joint: the model must be a tree, without loops")
        parent_joint[joint.child] = joint
    rooted = set()  # links whose chain of parents ends (at a root)
    for start in parent_joint:
        path, on_path, link = [], set(), start
        while link in parent_joint and link not in rooted:
            if link in on_path:
                loop = path[path.index(link):] + [link]
                joint = parent_joint[loop[-2]]
                shown = " -> ".join(printable(name) for name in reversed(loop))
                raise refuse(joint.element, f"joint {printable(joint.name)} <parent>",
                             f"link {printable(joint.parent)} closes a loop of joints "
                             f"({shown}); the model must be a tree, without loops")
            path.append(link)
            on_path.add(link)
            link = parent_joint[link].parent
        rooted.update(path)


def _check_couplings(model, joints, refuse):
    """No joint mimics another (URDF's `<mimic>`, SDFormat's `<axis><mimic>`): the station
    moves each joint on its own, so the coupling would be ignored."""
    for joint in joints:
        if joint.kind in FIXED_JOINT_TYPES:
            continue
        holders = [joint.element] if model.kind == "urdf" else [
            axis for axis in (joint.element.find("axis"), joint.element.find("axis2"))
            if axis is not None]
        for holder in holders:
            mimic = holder.find("mimic")
            if mimic is None:
                continue
            leader = printable(mimic.attrib.get("joint", ""))
            raise refuse(mimic, f"joint {printable(joint.name)} <mimic>",
                         f"it follows joint {leader}, a coupling the station does not keep "
                         "(its IK moves every joint on its own); remove <mimic> to move it as "
                         "a joint of its own, or make it fixed")


def _check_urdf_limits(joints, refuse):
    """A URDF joint's `<limit>` that Drake's plant cannot hold (it stops the process, not
    with an error): lower above upper, a negative velocity or acceleration. SDFormat's
    reader refuses these itself (a negative velocity there means none)."""
    for joint in joints:
        limit = joint.element.find("limit")
        if joint.kind in FIXED_JOINT_TYPES or limit is None:
            continue
        what = f"joint {printable(joint.name)} <limit"
        lower, upper = (_loose_number(limit, key) for key in ("lower", "upper"))
        if lower > upper:  # False where either is absent (NaN)
            raise refuse(limit, f"{what} lower upper>", f"lower {lower:g} is above upper "
                         f"{upper:g}; give the lower limit first")
        for key in ("velocity", "drake:acceleration"):
            value = _loose_number(limit, key)
            if value < 0:
                raise refuse(limit, f"{what} {key}>", f"{value:g} is negative; give "
                             "it as a positive number (it bounds both directions)")


def _loose_number(element, attribute):
    """`element`'s attribute as a float, NaN where it is absent or no number (Drake's
    reader names those)."""
    try:
        return float(original_text(element.attrib.get(attribute, "nan")))
    except ValueError:
        return math.nan


def _check_files(document, model, refuse):
    """Every mesh and texture the model reads (URDF's `filename`, SDFormat's `<uri>`) is
    on disk, not behind the network (Drake reads them when the station is built)."""
    folder = model.path.parent
    for element in document.walk():
        if model.kind == "urdf":
            uri = element.attrib.get("filename")
            what = f"<{element.tag} filename>"
        else:
            uri = element.text.strip() if element.tag == "uri" else None
            what = "<uri>"
        if uri is None:
            continue
        path = _url_path(uri, folder, lambda why: refuse(element, what, why))
        # An SDFormat <include> names a model's folder.
        if not (path.is_file() or (model.kind == "sdf" and path.is_dir())):
            raise refuse(element, what, f"{printable(uri)} is missing (no file at "
                         f"{printable(str(path))}); the meshes and textures a model names "
                         "are read from disk when the station is built")


def _number(element, attribute, default, refuse, what):
    """A finite float from `element`'s attribute (URDF) or child's text (SDFormat)."""
    if element is None:
        return default
    if attribute in element.attrib:
        text = element.attrib[attribute]
    elif element.find(attribute) is not None:
        text = element.find(attribute).text
    else:
        return default
    try:
        value = float(original_text(text))
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise refuse(element, what, f"{printable(text.strip())} is not a finite number")
    return value


def _inertial(model, link, refuse):
    """`(mass, 3x3 rotational inertia)` of `link` (Drake's defaults where it gives none:
    URDF's massless link, SDFormat's 1 kg and unit moments)."""
    name = printable(link.attrib.get("name", ""))
    inertial = link.find("inertial")
    if model.kind == "urdf":
        if inertial is None:
            return 0.0, ((0.0,) * 3,) * 3
        mass_element, tensor = inertial.find("mass"), inertial.find("inertia")
        mass = _number(mass_element, "value", 0.0, refuse, f"link {name} <mass value>")
    else:
        if inertial is None:
            return 1.0, ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
        tensor, mass_element = inertial.find("inertia"), inertial.find("mass") or inertial
        mass = _number(inertial, "mass", 1.0, refuse, f"link {name} <inertial><mass>")
    if mass < 0:
        raise refuse(mass_element, f"link {name} <inertial><mass>", f"{mass:g} kg is "
                     "negative; a mass is 0 or more")
    diagonal = 0.0 if model.kind == "urdf" else 1.0
    moments = {key: _number(tensor, key, diagonal if key in ("ixx", "iyy", "izz") else 0.0,
                            refuse, f"link {name} <inertia {key}>")
               for key in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")}
    return mass, ((moments["ixx"], moments["ixy"], moments["ixz"]),
                  (moments["ixy"], moments["iyy"], moments["iyz"]),
                  (moments["ixz"], moments["iyz"], moments["izz"]))


def _check_inertias(model, links, joints, motion, refuse):
    """Masses and inertias: finite, masses not negative; with dynamic motion, physical
    inertias, and every moving joint moves some mass (else the mass matrix is singular)."""
    inertials = {name: _inertial(model, link, refuse) for name, link in links.items()}
    if motion != "dynamic":
        return
    for name, (mass, inertia) in inertials.items():
        moments = _principal_moments(inertia)
        slack = INERTIA_TOLERANCE * max(abs(moments[0]), abs(moments[2]), 1e-12)
        link = links[name]
        element = link.find("inertial") or link
        what = f"link {printable(name)} <inertial><inertia>"
        if moments[0] < -slack:
            raise refuse(element, what, f"a principal moment of inertia is {moments[0]:g} "
                         "kg m^2; motion: dynamic needs them 0 or more")
        if moments[0] + moments[1] < moments[2] - slack:
            raise refuse(element, what, f"the principal moments {moments[0]:g}, "
                         f"{moments[1]:g}, {moments[2]:g} kg m^2 break the triangle "
                         "inequality (no body has one larger than the other two together); "
                         "motion: dynamic needs a physical inertia")
    children = {}
    for joint in joints:
        if joint.child in links:
            children.setdefault(joint.parent, []).append(joint.child)
    moved_mass = _moved_mass(links, children, inertials)
    for joint in joints:
        if joint.kind in FIXED_JOINT_TYPES or joint.child not in links:
            continue
        if moved_mass[joint.child] <= 0:
            moved, stack = [], [joint.child]
            while stack:  # a tree (checked): this ends
                moved.append(stack.pop())
                stack.extend(children.get(moved[-1], ()))
            element = links[joint.child].find("inertial") or links[joint.child]
            raise refuse(element, f"link {printable(joint.child)} <inertial><mass>",
                         f"joint {printable(joint.name)} moves only massless links "
                         f"({', '.join(printable(link) for link in moved)}); motion: dynamic "
                         "needs mass on what a joint moves (or use motion: kinematic)")


def _principal_moments(inertia):
    """The principal moments of a 3x3 inertia, smallest first (most files give a diagonal
    one: read without numpy's overhead, which counts over thousands of links)."""
    (ixx, ixy, ixz), (_, iyy, iyz), (_, _, izz) = inertia
    if ixy == ixz == iyz == 0:
        return sorted((ixx, iyy, izz))
    return [float(moment) for moment in np.linalg.eigvalsh(np.array(inertia))]


def _moved_mass(links, children, inertials):
    """{link: the mass of it and of everything hanging from it}, leaves first."""
    hanging = {child for below in children.values() for child in below}
    order, stack = [], [name for name in links if name not in hanging]
    while stack:
        order.append(stack.pop())
        stack.extend(children.get(order[-1], ()))
    total = {}
    for name in reversed(order):
        total[name] = inertials[name][0] + sum(total[child] for child in
                                                children.get(name, ()))
    return total
