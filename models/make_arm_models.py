"""Writes our models of two arms people own, the Franka Emika Panda and the KUKA LBR iiwa 14
R820, from their published kinematics and limits: `python models/make_arm_models.py`
rewrites pbp_drake_models/panda/pbp_panda.urdf and pbp_drake_models/iiwa/pbp_iiwa14.urdf
(the tests check that the files are what this writes).

What is published and taken as it is:
- Panda: the modified (Craig) DH table of Franka's documentation (control parameters),
  mapped to URDF joints as `rpy = (alpha, 0, 0)`, `xyz = (a, -sin(alpha) d, cos(alpha) d)`,
  the flange 0.107 m beyond joint 7; its joint position, velocity, acceleration and torque
  limits (the Panda's, not the FR3's).
- iiwa 14 R820: the joint origins (every lateral offset 0; segments 0.36, 0.42, 0.40 and
  0.126 m to the bare flange) and axes, its joint position limits, KUKA's velocity limits
  and the joints' torque limits. KUKA publishes no acceleration limits: the station takes
  `ArmStationConfig.default_acceleration_limit` for them.

What is ours: every shape (cylinders and boxes, no vendor mesh), the masses and inertias
(each link's shapes solid at DENSITY, combined about their centre of mass: computed, not
published), and the tool, a fixed two-finger hand whose tool point (`<arm>_ee`, z out of
the tool) is TOOL_LENGTH beyond the flange.
"""

import math
import textwrap
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent / "pbp_drake_models"
DENSITY = 1000.0  # kg/m^3: a link's shapes are solid at this density (ours)
TOOL_LENGTH = 0.10  # m from the flange to the tool point, between the fingertips (ours)
PI = math.pi


def panda():
    """The Panda: joints from the DH table `(a, d, alpha)`, limits per joint."""
    dh = [(0.0, 0.333, 0.0), (0.0, 0.0, -PI / 2), (0.0, 0.316, PI / 2),
          (0.0825, 0.0, PI / 2), (-0.0825, 0.384, -PI / 2), (0.0, 0.0, PI / 2),
          (0.088, 0.0, PI / 2)]
    upper = [2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973]
    lower = [-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973]
    velocity = [2.1750] * 4 + [2.6100] * 3
    acceleration = [15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0]
    effort = [87.0] * 4 + [12.0] * 3
    joints = [dict(xyz=(a, -math.sin(alpha) * d, math.cos(alpha) * d), rpy=(alpha, 0.0, 0.0),
                   lower=lo, upper=up, velocity=v, acceleration=acc, effort=e)
              for (a, d, alpha), lo, up, v, acc, e
              in zip(dh, lower, upper, velocity, acceleration, effort)]
    return dict(name="panda", title="Franka Emika Panda", joints=joints, flange=0.107,
                radius=0.06, base_radius=0.1)


def iiwa14():
    """The iiwa 14 R820: each joint's origin and orientation in its parent link."""
    origins = [((0, 0, 0.1575), (0, 0, 0)), ((0, 0, 0.2025), (PI / 2, 0, PI)),
               ((0, 0.2045, 0), (PI / 2, 0, PI)), ((0, 0, 0.2155), (PI / 2, 0, 0)),
               ((0, 0.1845, 0), (-PI / 2, PI, 0)), ((0, 0, 0.2155), (PI / 2, 0, 0)),
               ((0, 0.081, 0), (-PI / 2, PI, 0))]
    limits_degrees = [170, 120, 170, 120, 170, 120, 175]
    velocity_degrees = [85, 85, 100, 75, 130, 135, 135]
    effort = [320.0, 320.0, 176.0, 176.0, 110.0, 40.0, 40.0]
    joints = [dict(xyz=xyz, rpy=rpy, lower=-math.radians(q), upper=math.radians(q),
                   velocity=math.radians(v), acceleration=None, effort=e)
              for (xyz, rpy), q, v, e in zip(origins, limits_degrees, velocity_degrees, effort)]
    return dict(name="iiwa14", title="KUKA LBR iiwa 14 R820", joints=joints, flange=0.045,
                radius=0.065, base_radius=0.11)


def rotation_z_to(direction):
    """A rotation matrix whose z column is the unit `direction`."""
    z = np.asarray(direction, float) / np.linalg.norm(direction)
    helper = np.array([1.0, 0, 0]) if abs(z[0]) < 0.9 else np.array([0, 1.0, 0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def rpy_of(rotation):
    """URDF's roll, pitch, yaw of `rotation` (R = Rz(yaw) Ry(pitch) Rx(roll))."""
    pitch = math.asin(-max(-1.0, min(1.0, rotation[2, 0])))
    if abs(math.cos(pitch)) < 1e-9:
        return 0.0, pitch, math.atan2(-rotation[0, 1], rotation[1, 1])
    return (math.atan2(rotation[2, 1], rotation[2, 2]), pitch,
            math.atan2(rotation[1, 0], rotation[0, 0]))


def cylinder(name, start, end, radius):
    """A solid cylinder from `start` to `end` (link frame)."""
    start, end = np.asarray(start, float), np.asarray(end, float)
    return dict(name=name, kind="cylinder", size=(radius, float(np.linalg.norm(end - start))),
                center=(start + end) / 2, rotation=rotation_z_to(end - start))


def box(name, center, size):
    return dict(name=name, kind="box", size=tuple(size), center=np.asarray(center, float),
                rotation=np.eye(3))


def housing(name, radius):
    """The motor housing around a joint: a cylinder on the link's z (the joint's axis)."""
    return cylinder(name, (0, 0, -radius), (0, 0, radius), radius)


def mass_and_inertia(shapes):
    """`(mass, centre (3,), inertia about it (3, 3))` of solid `shapes` at DENSITY."""
    parts = []
    for shape in shapes:
        if shape["kind"] == "cylinder":
            radius, length = shape["size"]
            mass = DENSITY * PI * radius ** 2 * length
            local = np.diag([mass * (3 * radius ** 2 + length ** 2) / 12] * 2
                            + [mass * radius ** 2 / 2])
        else:
            x, y, z = shape["size"]
            mass = DENSITY * x * y * z
            local = np.diag([mass * (y * y + z * z), mass * (x * x + z * z),
                             mass * (x * x + y * y)]) / 12
        rotation = shape["rotation"]
        parts.append((mass, shape["center"], rotation @ local @ rotation.T))
    total = sum(mass for mass, _, _ in parts)
    centre = sum(mass * center for mass, center, _ in parts) / total
    inertia = np.zeros((3, 3))
    for mass, center, local in parts:
        offset = center - centre
        inertia += local + mass * (offset @ offset * np.eye(3) - np.outer(offset, offset))
    return total, centre, inertia


def number(value, digits=6):
    text = f"{value:.{digits}g}"
    return "0" if text in ("-0", "0") else text


def triple(values, digits=6):
    return " ".join(number(value, digits) for value in values)


def angles(values):
    """Angles to 12 digits: a joint's rpy at 6 would move the flange by a micrometre."""
    return triple(values, 12)


def link_xml(name, shapes, material):
    mass, centre, inertia = mass_and_inertia(shapes)
    lines = [f'  <link name="{name}">', "    <inertial>",
             f'      <origin xyz="{triple(centre)}" rpy="0 0 0"/>',
             f'      <mass value="{number(mass)}"/>',
             f'      <inertia ixx="{number(inertia[0, 0])}" ixy="{number(inertia[0, 1])}" '
             f'ixz="{number(inertia[0, 2])}" iyy="{number(inertia[1, 1])}" '
             f'iyz="{number(inertia[1, 2])}" izz="{number(inertia[2, 2])}"/>',
             "    </inertial>"]
    for shape in shapes:
        origin = (f'      <origin xyz="{triple(shape["center"])}" '
                  f'rpy="{angles(rpy_of(shape["rotation"]))}"/>')
        if shape["kind"] == "cylinder":
            geometry = (f'<cylinder radius="{number(shape["size"][0])}" '
                        f'length="{number(shape["size"][1])}"/>')
        else:
            geometry = f'<box size="{triple(shape["size"])}"/>'
        for element in ("visual", "collision"):
            lines += [f'    <{element} name="{shape["name"]}">', origin,
                      f"      <geometry>{geometry}</geometry>"]
            if element == "visual":
                lines.append(f'      <material name="{material}"/>')
            lines.append(f"    </{element}>")
    lines.append("  </link>")
    return lines


def shapes_of_links(arm):
    """Each link's shapes: its motor housing, a cylinder to the next joint (or flange),
    and on the last link the flange and our two-finger tool."""
    name, radius, joints = arm["name"], arm["radius"], arm["joints"]
    links = [[cylinder("foot", (0, 0, 0), (0, 0, 0.02), arm["base_radius"]),
              cylinder("column", (0, 0, 0), joints[0]["xyz"], radius)]]
    for index in range(len(joints)):
        shapes = [housing("housing", radius)]
        offset = (joints[index + 1]["xyz"] if index + 1 < len(joints)
                  else (0.0, 0.0, arm["flange"]))
        if np.linalg.norm(offset) > 0.01:
            shapes.append(cylinder("segment", (0, 0, 0), offset, radius * 0.9))
        links.append(shapes)
    flange = arm["flange"]
    links[-1] += [box("palm", (0, 0, flange + 0.02), (0.06, 0.16, 0.04)),
                  box("finger_left", (0, 0.04, flange + 0.04 + (TOOL_LENGTH - 0.02) / 2),
                      (0.02, 0.015, TOOL_LENGTH - 0.02)),
                  box("finger_right", (0, -0.04, flange + 0.04 + (TOOL_LENGTH - 0.02) / 2),
                      (0.02, 0.015, TOOL_LENGTH - 0.02))]
    return [(f"{name}_link{index}", shapes) for index, shapes in enumerate(links)]


def urdf(arm, header):
    name = arm["name"]
    lines = ['<?xml version="1.0"?>', "<!--", *header, "-->",
             f'<robot name="pbp_{name}" xmlns:drake="http://drake.mit.edu">',
             f'  <material name="{name}_grey"><color rgba="0.85 0.85 0.87 1"/></material>',
             f'  <material name="{name}_dark"><color rgba="0.30 0.30 0.32 1"/></material>', ""]
    for index, (link, shapes) in enumerate(shapes_of_links(arm)):
        lines += link_xml(link, shapes, f"{name}_dark" if index == 0 else f"{name}_grey")
        lines.append("")
    lines += [f'  <link name="{name}_ee"/>', ""]
    for index, joint in enumerate(arm["joints"], start=1):
        acceleration = ("" if joint["acceleration"] is None
                        else f' drake:acceleration="{number(joint["acceleration"])}"')
        lines += [f'  <joint name="{name}_joint{index}" type="revolute">',
                  f'    <parent link="{name}_link{index - 1}"/>',
                  f'    <child link="{name}_link{index}"/>',
                  f'    <origin xyz="{triple(joint["xyz"])}" rpy="{angles(joint["rpy"])}"/>',
                  '    <axis xyz="0 0 1"/>',
                  f'    <limit lower="{number(joint["lower"], 12)}" '
                  f'upper="{number(joint["upper"], 12)}" '
                  f'velocity="{number(joint["velocity"], 12)}" effort="{number(joint["effort"])}"'
                  f'{acceleration}/>',
                  "  </joint>", ""]
    count = len(arm["joints"])
    lines += [f'  <joint name="{name}_ee_joint" type="fixed">',
              f'    <parent link="{name}_link{count}"/>', f'    <child link="{name}_ee"/>',
              f'    <origin xyz="0 0 {number(arm["flange"] + TOOL_LENGTH)}" rpy="0 0 0"/>',
              "  </joint>", ""]
    for index in range(1, count + 1):
        lines += [f'  <transmission name="{name}_transmission{index}">',
                  "    <type>transmission_interface/SimpleTransmission</type>",
                  f'    <joint name="{name}_joint{index}"><hardwareInterface>'
                  "EffortJointInterface</hardwareInterface></joint>",
                  f'    <actuator name="{name}_motor{index}"><mechanicalReduction>1'
                  "</mechanicalReduction></actuator>", "  </transmission>", ""]
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def header(arm, source):
    """The file's comment: what it is, what is published and what is ours, its frames."""
    name = arm["name"]
    paragraphs = [
        f"pbp_{name}: our model of the {arm['title']} for pbp_drake, written by "
        "models/make_arm_models.py (edit that, not this file).",
        f"Published and taken as it is: {source}",
        "Ours: every shape (primitive cylinders and boxes; no vendor mesh is used), the masses "
        f"and inertias (each link's shapes solid at {number(DENSITY)} kg/m^3: computed, not "
        "published), and the tool: a fixed two-finger hand whose tool point "
        f"{name}_ee lies {number(TOOL_LENGTH)} m beyond the flange, its z axis out of the tool.",
        f"Frames: {name}_link0 is the base (its frame on the floor or table, z up); weld it to "
        f"the world where the arm stands. {name}_joint1..7 turn about their z axes. "
        "<transmission> gives every joint a motor (its effort the joint's torque limit)."]
    lines = []
    for paragraph in paragraphs:
        lines += textwrap.wrap(paragraph, 90, initial_indent="  ", subsequent_indent="  ")
        lines.append("")
    return lines[:-1]


def models():
    """`{path: text}` of the models this writes."""
    panda_source = ("the joints from Franka's modified DH table and the Panda's joint position, "
                    "velocity, acceleration and torque limits (Franka documentation, control "
                    "parameters); the flange 0.107 m beyond joint 7.")
    iiwa_source = ("the joint origins and axes (lateral offsets 0; segments 0.36, 0.42, 0.40 and "
                   "0.126 m to the bare flange), the joint position limits, KUKA's velocity "
                   "limits and the joint torque limits. KUKA publishes no acceleration limits.")
    arms = [(panda(), panda_source, HERE / "panda" / "pbp_panda.urdf"),
            (iiwa14(), iiwa_source, HERE / "iiwa" / "pbp_iiwa14.urdf")]
    return {path: urdf(arm, header(arm, source)) for arm, source, path in arms}


if __name__ == "__main__":
    for path, text in models().items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
        print(f"wrote {path}")
