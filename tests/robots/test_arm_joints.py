"""A user's own arm whose joints the station would move other than the file says (a
coupling it ignores, limits Drake cannot hold, a base the file welds itself) is refused in
one line naming the field, the file and the joint; a prismatic joint's travel counts in the
arm's reach. Each model is a three-joint arm written in tmp_path."""

import dataclasses

import numpy as np

import pytest

from pbp_drake.robots import ArmStationConfig, arm_reach, make_arm_station

ARM = """<?xml version="1.0"?>
<robot name="arm3" xmlns:drake="http://drake.mit.edu">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0 0 0.15"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l3"><inertial><origin xyz="0.15 0 0"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-2.5" upper="2.5" velocity="1.5" effort="10"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" velocity="1.5" effort="10"/></joint>
  <joint name="j3" type="{j3_type}"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.4 0 0"/><axis xyz="{j3_axis}"/>
    <limit {j3_limit}/>{j3_extra}</joint>
  <joint name="jt" type="fixed"><parent link="l3"/><child link="tool"/>
    <origin xyz="0.3 0 0" rpy="0 1.5708 0"/></joint>
</robot>
"""
J3 = {"j3_type": "revolute", "j3_axis": "0 1 0",
      "j3_limit": 'lower="-2" upper="2" velocity="1.5" effort="10"', "j3_extra": ""}
READY = [0.0, 0.5, -0.5]
SDF_ARM = """<?xml version="1.0"?>
<sdf version="1.11" xmlns:drake="http://drake.mit.edu">
  <model name="two_joints">
    <link name="base"/>
    <link name="upper"><pose>0 0 0.2 0 0 0</pose></link>
    <link name="lower"><pose>0 0 0.5 0 0 0</pose></link>
    <frame name="tool" attached_to="lower">
      <pose relative_to="lower">0 0 0.1 0 1.5708 0</pose></frame>
    <joint name="shoulder" type="revolute"><parent>base</parent><child>upper</child>
      <axis><xyz>0 0 1</xyz>
        <limit><lower>-1</lower><upper>1</upper><velocity>1</velocity></limit></axis>
    </joint>
    <joint name="elbow" type="revolute"><parent>upper</parent><child>lower</child>
      <axis><xyz>0 1 0</xyz>
        <limit><lower>-1</lower><upper>1</upper><velocity>1</velocity>{elbow_limit}</limit>
        {elbow_extra}</axis>
    </joint>
  </model>
</sdf>
"""


def arm(tmp_path, **j3):
    """The three-joint arm with joint j3's fields of `j3` (J3's otherwise), and its config."""
    path = tmp_path / "arm3.urdf"
    path.write_text(ARM.format(**{**J3, **j3}))
    return path, ArmStationConfig(model_file=str(path), base_frame="base", ee_frame="tool",
                                  initial_positions=list(READY))


# The line of j3's <limit>, where what the tests add to the joint stands too.
J3_LINE = ARM[:ARM.index("<limit {j3_limit}")].count("\n") + 1


def sdf_arm(tmp_path, elbow_limit="", elbow_extra=""):
    """The two-joint SDFormat arm with `elbow_limit` in its elbow's <limit> and
    `elbow_extra` in its <axis>, and its config."""
    path = tmp_path / "arm.sdf"
    path.write_text(SDF_ARM.format(elbow_limit=elbow_limit, elbow_extra=elbow_extra))
    return path, ArmStationConfig(model_file=str(path), base_frame="base", ee_frame="tool")


def refusal(config):
    """The one-line message `make_arm_station` refuses `config` with."""
    with pytest.raises(ValueError) as error:
        make_arm_station(config)
    message = str(error.value)
    assert "\n" not in message, message
    return message


def test_the_arm_of_these_tests_loads(tmp_path):
    _, config = arm(tmp_path)
    make_arm_station(config)


@pytest.mark.parametrize("motion", ["kinematic", "dynamic"])
def test_a_mimic_joint_is_refused_naming_it(tmp_path, motion):
    # Drake's plant couples j3 to j2; the station's IK would move it on its own.
    path, config = arm(tmp_path, j3_extra='<mimic joint="j2" multiplier="-1" offset="0"/>')
    config = dataclasses.replace(config, motion=motion)
    assert (f"ArmStationConfig.model_file '{path}': line {J3_LINE}, joint 'j3' <mimic>: it "
            "follows joint 'j2', a coupling the station does not keep" in refusal(config))


def test_an_sdformat_mimic_joint_is_refused_naming_it(tmp_path):
    # Drake reads SDFormat's <mimic> and keeps nothing of it: the joint moved freely.
    make_arm_station(sdf_arm(tmp_path)[1])
    path, config = sdf_arm(
        tmp_path, elbow_extra='<mimic joint="shoulder"><multiplier>1</multiplier></mimic>')
    line = SDF_ARM[:SDF_ARM.index("{elbow_extra}")].count("\n") + 1
    assert (f"'{path}': line {line}, joint 'elbow' <mimic>: it follows joint 'shoulder'"
            in refusal(config))


@pytest.mark.parametrize("limit, what", [
    ('lower="2" upper="-2" velocity="1.5"', "<limit lower upper>: lower 2 is above upper -2; "
     "give the lower limit first"),
    ('lower="-2" upper="2" velocity="-1.5"', "<limit velocity>: -1.5 is negative"),
    ('lower="-2" upper="2" velocity="1.5" drake:acceleration="-3"',
     "<limit drake:acceleration>: -3 is negative"),
], ids=["inverted", "negative velocity", "negative acceleration"])
def test_urdf_limits_drake_cannot_hold_are_refused_naming_them(tmp_path, limit, what):
    # Drake's plant stopped the process on these (exit 1, "Failure at ... joint.h").
    path, config = arm(tmp_path, j3_limit=limit)
    assert (f"ArmStationConfig.model_file '{path}': line {J3_LINE}, joint 'j3' {what}"
            in refusal(config))


def test_a_continuous_joint_with_inverted_limits_is_refused_too(tmp_path):
    path, config = arm(tmp_path, j3_type="continuous",
                       j3_limit='lower="1" upper="-1" velocity="1.5"')
    assert "joint 'j3' <limit lower upper>: lower 1 is above upper -1" in refusal(config)


@pytest.mark.parametrize("kind", ["URDF", "SDFormat"])
def test_a_zero_acceleration_limit_is_refused_not_replaced(tmp_path, kind):
    # It was replaced by default_acceleration_limit (10 rad/s^2), unlike the file.
    if kind == "URDF":
        path, config = arm(tmp_path, j3_limit=f'{J3["j3_limit"]} drake:acceleration="0"')
        joint = "j3"
    else:
        path, config = sdf_arm(tmp_path, "<drake:acceleration>0</drake:acceleration>")
        joint = "elbow"
    assert (f"ArmStationConfig.model_file '{path}': joint '{joint}' has an acceleration limit "
            "of 0: it could never move; give a positive drake:acceleration in the model, or "
            "none (then ArmStationConfig.default_acceleration_limit)" in refusal(config))


@pytest.mark.parametrize("ready", [0.0, 0.4])
def test_a_prismatic_joint_s_travel_counts_in_the_reach(tmp_path, ready):
    # A telescope along l3 (0 to 0.4 m): the reach was measured in the ready configuration
    # alone, 1.0 m retracted, and goals it reaches extended were refused as beyond it.
    _, config = arm(tmp_path, j3_type="prismatic", j3_axis="1 0 0",
                    j3_limit='lower="0" upper="0.4" velocity="0.5"')
    config = dataclasses.replace(config, initial_positions=[0.0, 0.5, ready])
    shoulder, reach = arm_reach(config)
    np.testing.assert_allclose(shoulder, [0.0, 0.0, 0.1])
    # Shoulder to j2 0.3 m, j2 to the tool 0.4 + 0.3 m and the 0.4 m of travel.
    assert reach == pytest.approx(1.4)


def test_a_prismatic_first_joint_s_travel_counts_in_the_reach(tmp_path):
    # A vertical lift under the arm (0 to 0.5 m) moves the shoulder itself.
    path, config = arm(tmp_path)
    path.write_text(path.read_text().replace(
        '<joint name="j1" type="revolute"', '<joint name="j1" type="prismatic"').replace(
        'lower="-2.5" upper="2.5"', 'lower="0" upper="0.5"'))
    _, reach = arm_reach(dataclasses.replace(config, initial_positions=[0.0, 0.5, -0.5]))
    assert reach == pytest.approx(0.3 + 0.4 + 0.3 + 0.5)


def test_a_base_the_file_welds_to_the_world_is_refused_saying_what_to_do(tmp_path):
    # URDFs from ROS often weld their base to a "world" link; the message told the user to
    # "name the link the arm stands on", which they had.
    path, config = arm(tmp_path)
    path.write_text(path.read_text().replace('<link name="base"/>', """<link name="base"/>
  <link name="world"/>
  <joint name="world_weld" type="fixed"><parent link="world"/><child link="base"/></joint>"""))
    assert refusal(config) == (
        "ArmStationConfig.base_frame 'base' is fixed to the world by the model itself (joint "
        "'world_weld'); remove that joint (and the world link) from the model file: the "
        "station welds base_frame to the world at base_pose")
    assert refusal(dataclasses.replace(config, base_frame="world")).endswith(
        "(its links: base, l1, l2, l3, tool); the world is not the model's: name one of its "
        "links")
