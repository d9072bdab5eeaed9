"""The geometry an arm's model file fixes to its base (its pedestal), read from the file's
XML (`pbp_drake.robots.model_checks`), and whether a box of the scene overlaps it: the
scene's objects must not stand inside the robot. Primitives only (boxes, cylinders,
spheres); meshes are left out.
"""

import dataclasses
import math

import numpy as np
from pydrake.math import RigidTransform, RollPitchYaw

from pbp_drake.robots.model_checks import (
    FIXED_JOINT_TYPES, check_model_file, links_and_joints, original_text, printable)


@dataclasses.dataclass(frozen=True)
class Shape:
    """A primitive of the model's geometry: `kind` box (`size` its three sides), cylinder
    (radius, length) or sphere (radius), posed by `pose` (4x4) in the base frame; `where`
    names it (`link 'x' <collision 'y'>`), `line` is its line in the file."""

    kind: str
    size: tuple
    pose: np.ndarray
    where: str
    line: int

    def describe(self):
        if self.kind == "box":
            return "a box of sides " + " x ".join(f"{side:g}" for side in self.size) + " m"
        if self.kind == "cylinder":
            return f"a cylinder of radius {self.size[0]:g} m, length {self.size[1]:g} m"
        return f"a sphere of radius {self.size[0]:g} m"


def _pose(xyz, rpy):
    """The 4x4 pose of URDF's and SDFormat's `xyz` and `rpy` (about the fixed x, then y,
    then z axes: Drake's RollPitchYaw)."""
    return RigidTransform(RollPitchYaw(rpy), xyz).GetAsMatrix4()


def _floats(text, count):
    try:
        values = [float(value) for value in original_text(text).split()]
    except ValueError:
        return None
    return values if len(values) == count and all(map(math.isfinite, values)) else None


def _element_pose(model, element):
    """The pose of a URDF `<origin>` or an SDFormat `<pose>` child of `element` in its
    link's frame; None for an SDFormat pose relative to another frame."""
    if model.kind == "urdf":
        origin = element.find("origin")
        if origin is None:
            return np.eye(4)
        xyz = _floats(origin.attrib.get("xyz", "0 0 0"), 3)
        rpy = _floats(origin.attrib.get("rpy", "0 0 0"), 3)
        return None if xyz is None or rpy is None else _pose(xyz, rpy)
    pose = element.find("pose")
    if pose is None:
        return np.eye(4)
    if pose.attrib.get("relative_to"):
        return None
    values = _floats(pose.text, 6)
    return None if values is None else _pose(values[:3], values[3:])


def _link_shapes(model, link, link_pose):
    """The primitives of `link` (its collision geometry, else its visual) in the base
    frame, the link at `link_pose` there."""
    shapes = []
    elements = link.find_all("collision") or link.find_all("visual")
    for element in elements:
        geometry, pose = element.find("geometry"), _element_pose(model, element)
        if geometry is None or pose is None or not geometry.children:
            continue
        shape = geometry.children[0]
        if model.kind == "urdf":
            size = {"box": _floats(shape.attrib.get("size", ""), 3),
                    "cylinder": _floats(f"{shape.attrib.get('radius', '')} "
                                        f"{shape.attrib.get('length', '')}", 2),
                    "sphere": _floats(shape.attrib.get("radius", ""), 1)}.get(shape.tag)
        else:
            parts = {"box": ("size",), "cylinder": ("radius", "length"),
                     "sphere": ("radius",)}.get(shape.tag, ())
            texts = [shape.find(part).text if shape.find(part) is not None else ""
                     for part in parts]
            size = _floats(" ".join(texts), 3 if shape.tag == "box" else len(parts))
        if size is None:
            continue  # a mesh, or sizes Drake will refuse itself
        where = (f"link {printable(link.attrib.get('name', ''))} <{element.tag} "
                 f"{printable(element.attrib.get('name', ''))}>")
        shapes.append(Shape(shape.tag, tuple(size), link_pose @ pose, where, element.line))
    return shapes


def base_shapes(model, base_frame):
    """The primitives (`Shape`) of the link named `base_frame` and, in a URDF, of the
    links welded to it by fixed joints, in the base frame."""
    links, joints = links_and_joints(model)
    if base_frame not in links:
        return []
    shapes, stack = [], [(base_frame, np.eye(4))]
    while stack:  # the tree is checked: this ends
        name, pose = stack.pop()
        shapes += _link_shapes(model, links[name], pose)
        if model.kind != "urdf":
            continue
        for joint in joints:
            if joint.parent == name and joint.kind in FIXED_JOINT_TYPES and joint.child in links:
                origin = _element_pose(model, joint.element)
                if origin is not None:
                    stack.append((joint.child, pose @ origin))
    return shapes


def first_overlap(shapes, base_pose, lower, upper):
    """The first of `shapes` (in the base frame; the base at `base_pose` [x, y, z, yaw] in
    the world) that overlaps the world box from `lower` to `upper` (3,) (a point when
    they are equal), or None."""
    x, y, z, yaw = base_pose
    world = _pose([x, y, z], [0.0, 0.0, yaw])
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    center, half = (lower + upper) / 2, (upper - lower) / 2
    for shape in shapes:
        pose = world @ shape.pose
        rotation, origin = pose[:3, :3], pose[:3, 3]
        if shape.kind == "sphere":
            if np.linalg.norm(np.clip(origin, lower, upper) - origin) < shape.size[0]:
                return shape
            continue
        if shape.kind == "cylinder" and abs(abs(rotation[2, 2]) - 1.0) < 1e-9:
            radius, length = shape.size
            nearest = np.clip(origin[:2], lower[:2], upper[:2])
            if (np.linalg.norm(nearest - origin[:2]) < radius
                    and abs(origin[2] - center[2]) < half[2] + length / 2):
                return shape
            continue
        # A box, or a tilted cylinder as the box around it: separating axes.
        sides = (np.array(shape.size) / 2 if shape.kind == "box"
                 else np.array([shape.size[0], shape.size[0], shape.size[1] / 2]))
        if _boxes_overlap(origin, rotation, sides, center, half):
            return shape
    return None


def _boxes_overlap(center, rotation, half, box_center, box_half):
    """Whether a box (centre, rotation, half sides) and a world-aligned box overlap."""
    offset = center - box_center
    axes = [*np.eye(3), *rotation.T]
    axes += [np.cross(a, b) for a in np.eye(3) for b in rotation.T]
    for axis in axes:
        if np.linalg.norm(axis) < 1e-9:
            continue
        reach = np.sum(np.abs(rotation.T @ axis) * half) + np.sum(np.abs(axis) * box_half)
        if abs(offset @ axis) >= reach:
            return False
    return True


def check_clear_of_base(config, boxes, field="ArmStationConfig.model_file"):
    """Raises ValueError when one of `boxes` (`(what, lower, upper)`: a world box, or a
    point when lower == upper, and the words naming it) overlaps the geometry the model
    of `config` (an `ArmStationConfig`) fixes to its base, where the base stands."""
    model = check_model_file(config.model_file, config.motion, field)
    shapes = base_shapes(model, config.base_frame)
    for what, lower, upper in boxes:
        shape = first_overlap(shapes, config.base_pose, lower, upper)
        if shape is not None:
            verb = "is inside" if np.array_equal(lower, upper) else "reaches into"
            raise ValueError(f"{what} {verb} the robot's own geometry: {shape.where} "
                             f"({shape.describe()}) of {field} "
                             f"{printable(config.model_file)}, line {shape.line}, its base "
                             f"at {list(config.base_pose)}; move it out")
