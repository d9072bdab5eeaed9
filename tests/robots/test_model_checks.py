"""A user's arm model file that would hang, fail at build or mid-run, or print unreadable
names is refused before anything is built: one line naming the scenario's field, the file,
the element and its field, within 2 s, and `pbp-drake run`/`study` exit 2. Each bad file
is our arm's (models/) with one change."""

import dataclasses
import pathlib
import re
import subprocess
import sys
import time

import pytest

from pbp_drake.cli import main
from pbp_drake.robots import ArmStationConfig, make_arm_station
from pbp_drake.robots.hsr_model import models_dir
from pbp_drake.robots.model_checks import MAX_MODEL_FILE_BYTES
from pbp_drake.robots.model_geometry import check_clear_of_base
from pbp_drake.scenarios import DynamicObstacles, ScenarioError, load_scenario_file, resolve

REPO = pathlib.Path(__file__).resolve().parents[2]
ARM_REACH = REPO / "diagrams" / "arm_reach.yaml"
ARM7 = models_dir() / "pbp_drake_models" / "arm7" / "pbp_arm7.urdf"
ARM6 = pathlib.Path(__file__).resolve().parent / "models" / "pbp_arm6_other.urdf"
# The checks read a file of a few KB; 2 s is the bound a user is promised, and far more
# than they take on a loaded machine (a hang or a Drake build would exceed it).
TIME_BOUND = 2.0


def arm7_with(tmp_path, old, new, count=1):
    """Our arm's file with `old` replaced by `new` (`count` times), written in tmp_path."""
    text = ARM7.read_text()
    assert text.count(old) >= count, old
    path = tmp_path / "arm.urdf"
    path.write_text(text.replace(old, new, count))
    return path


def line_of(text):
    """The line of our arm's file where `text` first stands (where an edit of it is)."""
    source = ARM7.read_text()
    return source[:source.index(text)].count("\n") + 1


def scenario_of(model_file, motion="kinematic", **task_changes):
    scenario = load_scenario_file(ARM_REACH).scenario
    robot = dataclasses.replace(scenario.robot, model_file=str(model_file), motion=motion)
    return dataclasses.replace(scenario, robot=robot,
                               task=dataclasses.replace(scenario.task, **task_changes))


def refusal(scenario):
    """The one-line message `resolve` refuses `scenario` with, checked to come within
    TIME_BOUND."""
    started = time.monotonic()
    with pytest.raises(ScenarioError) as error:
        resolve(scenario)
    elapsed = time.monotonic() - started
    message = str(error.value)
    assert elapsed < TIME_BOUND, (elapsed, message)
    assert "\n" not in message and "\r" not in message, message
    return message


@pytest.mark.parametrize("model_file", [ARM7, ARM6], ids=["arm7", "arm6"])
@pytest.mark.parametrize("motion", ["kinematic", "dynamic"])
def test_our_arms_pass_in_either_motion(model_file, motion):
    scenario = scenario_of(model_file, motion)
    if model_file == ARM6:
        ready = ARM6.read_text().split("ready configuration: [")[1].split("]")[0]
        scenario = dataclasses.replace(scenario, robot=dataclasses.replace(
            scenario.robot, base_frame="arm6_base", ee_frame="arm6_tool",
            initial_positions=[float(value) for value in ready.split(",")]))
    started = time.monotonic()
    resolve(scenario)
    assert time.monotonic() - started < TIME_BOUND


JOINT1_PARENT = '<parent link="arm7_base"/>\n    <child link="arm7_link1"/>'


@pytest.mark.slow
def test_a_joint_cycle_is_refused_by_the_cli_with_exit_2_and_no_hang(tmp_path):
    # The shoulder hangs from the upper arm, which hangs from the shoulder: the chain walk
    # from the hand to the base used to loop forever, growing.
    model = arm7_with(tmp_path, JOINT1_PARENT,
                      '<parent link="arm7_link3"/>\n    <child link="arm7_link1"/>')
    scenario_file = tmp_path / "cycle.yaml"
    scenario_file.write_text(ARM_REACH.read_text().replace(
        "package://pbp_drake_models/arm7/pbp_arm7.urdf", str(model)))
    started = time.monotonic()
    # A subprocess, so that a hang fails the test at the timeout instead of stalling it;
    # its time includes importing Drake.
    done = subprocess.run([sys.executable, "-m", "pbp_drake", "run", str(scenario_file),
                           "--no-meshcat", "--log", str(tmp_path / "ticks.csv")],
                          capture_output=True, text=True, timeout=120, cwd=REPO)
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr, done.stderr
    assert (f"scenario.robot.model_file '{model}': line " in lines[0]
            and "<parent>: link 'arm7_link" in lines[0] and "closes a loop of joints" in lines[0]
            ), lines[0]
    assert not (tmp_path / "ticks.csv").exists()
    assert time.monotonic() - started < 120
    assert refusal(scenario_of(model))  # and in-process, within the bound


def test_a_study_of_a_bad_model_exits_2_and_writes_nothing(tmp_path, capsys):
    model = arm7_with(tmp_path, '<mass value="0.6"/>', '<mass value="-0.6"/>')
    scenario_file = tmp_path / "negative.yaml"
    scenario_file.write_text(ARM_REACH.read_text().replace(
        "package://pbp_drake_models/arm7/pbp_arm7.urdf", str(model)))
    started = time.monotonic()
    code = main(["study", str(scenario_file), "--trials", "2", "--jobs", "1",
                 "--output", str(tmp_path / "study")])
    assert time.monotonic() - started < TIME_BOUND
    assert code == 2
    assert "link 'arm7_link7' <inertial><mass>: -0.6 kg is negative" in capsys.readouterr().err
    assert not (tmp_path / "study").exists()


JOINT5 = '<joint name="arm7_joint5"'


def test_a_link_with_two_parents_is_refused(tmp_path):
    model = arm7_with(tmp_path, '<parent link="arm7_link6"/>\n    <child link="arm7_link7"/>',
                      '<parent link="arm7_link6"/>\n    <child link="arm7_link5"/>')
    message = refusal(scenario_of(model))
    assert (f"joint 'arm7_joint7' <child>: link 'arm7_link5' already hangs from joint "
            f"'arm7_joint5' (line {line_of(JOINT5)}); a link hangs from one joint"
            in message), message


def test_a_joint_to_a_link_that_is_not_there_is_refused_in_drake_s_words(tmp_path):
    model = arm7_with(tmp_path, '<child link="arm7_link7"/>', '<child link="nowhere"/>')
    message = refusal(scenario_of(model))
    assert ("does not load: " in message
            and "Could not find link named 'nowhere'" in message), message


@pytest.mark.parametrize("uri, why", [
    ("meshes/foot.obj", "is missing (no file at"),
    ("package://drake_models/iiwa_description/meshes/link_0.obj",
     "needs the network (Drake downloads package://drake_models)"),
    ("https://example.com/foot.obj", "is a URL: reading it needs the network"),
    ("package://someone_else/foot.obj", "is in package 'someone_else', which the station "
     "does not know"),
    ("file:///nowhere/foot.obj", "is missing (no file at '/nowhere/foot.obj')"),
    ("package://drake/nowhere/foot.obj", "is missing (no file at"),
], ids=["missing", "drake_models", "url", "unknown package", "file url", "drake package"])
def test_a_mesh_that_is_missing_or_needs_the_network_is_refused(tmp_path, uri, why):
    old = '<geometry><cylinder radius="0.12" length="0.02"/></geometry>'
    model = arm7_with(tmp_path, old, f'<geometry><mesh filename="{uri}"/></geometry>')
    message = refusal(scenario_of(model))
    assert (f"scenario.robot.model_file '{model}': line {line_of(old)}, <mesh filename>: '{uri}' "
            f"{why}" in message), message


def test_a_mesh_next_to_the_model_is_read(tmp_path):
    old = '<geometry><cylinder radius="0.12" length="0.02"/></geometry>'
    model = arm7_with(tmp_path, old, '<geometry><mesh filename="meshes/foot.obj"/></geometry>')
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "foot.obj").write_text(
        "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
    resolve(scenario_of(model))


LINK3_MASS = '<mass value="3.6"/>'


@pytest.mark.parametrize("write, what", [
    (lambda path: path.write_text('<?xml version="1.0"?>\n<model name="arm"/>\n'),
     "line 2, <model>: expected a URDF <robot> or an SDFormat <sdf><model> as the top "
     "element"),
    (lambda path: path.write_bytes(ARM7.read_text().replace(
        '<robot name="pbp_arm7"', '<robot name="pbp_arm7_\xe9"').encode("latin-1")),
     "the file: byte "),
    (lambda path: path.write_text(ARM7.read_text().replace(LINK3_MASS,
                                                           '<mass value="heavy"/>')),
     f"line {line_of(LINK3_MASS)}, link 'arm7_link3' <mass value>: 'heavy' is not a finite "
     "number"),
], ids=["not a model", "not UTF-8", "a word for a number"])
def test_a_file_that_is_no_readable_model_is_refused(tmp_path, write, what):
    model = tmp_path / "arm.urdf"
    write(model)
    message = refusal(scenario_of(model))
    assert f"scenario.robot.model_file '{model}': {what}" in message, message


def test_a_negative_mass_is_refused_in_either_motion(tmp_path):
    model = arm7_with(tmp_path, LINK3_MASS, '<mass value="-3.6"/>')
    for motion in ("kinematic", "dynamic"):
        message = refusal(scenario_of(model, motion))
        assert (f"line {line_of(LINK3_MASS)}, link 'arm7_link3' <inertial><mass>: "
                "-3.6 kg is negative"
                in message), message


ZERO_LINK7 = ('<mass value="0.6"/>\n      <inertia ixx="0.000453272" ixy="0" ixz="0" '
              'iyy="0.000294424" iyz="0" izz="0.000511393"/>',
              '<mass value="0"/>\n      <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" '
              'izz="0"/>')


def test_a_massless_link_a_joint_moves_is_refused_for_dynamic_motion_only(tmp_path):
    model = arm7_with(tmp_path, *ZERO_LINK7)
    message = refusal(scenario_of(model, "dynamic"))
    assert ("link 'arm7_link7' <inertial><mass>: joint 'arm7_joint7' moves only massless "
            "links ('arm7_link7', 'arm7_ee'); motion: dynamic needs mass" in message), message
    # Kinematic motion steps no dynamics: the station puts the joints where the IK says.
    resolve(scenario_of(model, "kinematic"))


def test_an_inertia_no_body_has_is_refused_for_dynamic_motion(tmp_path):
    # izz larger than ixx + iyy: the triangle inequality of principal moments broken.
    model = arm7_with(tmp_path, 'izz="0.000511393"', 'izz="0.00511393"')
    message = refusal(scenario_of(model, "dynamic"))
    assert (f"line {line_of(ZERO_LINK7[0]) - 2}, link 'arm7_link7' <inertial><inertia>: the "
            "principal moments "
            in message and "break the triangle inequality" in message), message
    resolve(scenario_of(model, "kinematic"))


def test_a_negative_moment_of_inertia_is_refused_for_dynamic_motion(tmp_path):
    model = arm7_with(tmp_path, 'ixx="0.000453272"', 'ixx="-0.000453272"')
    message = refusal(scenario_of(model, "dynamic"))
    assert ("link 'arm7_link7' <inertial><inertia>: a principal moment of inertia is "
            "-0.000453272 kg m^2" in message), message


def test_a_joint_that_turns_no_inertia_is_refused_for_dynamic_motion(tmp_path):
    # The wrist roll turns a point mass on its own axis (and nothing else): mass, but no
    # inertia about the axis; Drake's dynamics would fail mid-run.
    old, _ = ZERO_LINK7
    model = arm7_with(tmp_path, old.replace('xyz="0 0 0.0212048"', ""),
                      '<mass value="0.6"/>\n      <inertia ixx="0" ixy="0" ixz="0" iyy="0" '
                      'iyz="0" izz="0"/>')
    message = refusal(scenario_of(model, "dynamic"))
    assert ("joint 'arm7_joint7' moves no inertia about its axis (the mass matrix is "
            "singular in the ready configuration): link 'arm7_link7'" in message), message


LINK2 = '<link name="arm7_link2">'


@pytest.mark.parametrize("written, shown", [
    ("arm7_&#0;link2", r"'arm7_\x00link2'"),
    ("arm7_\nlink2", r"'arm7_\nlink2'"),
    ("arm7_&#10;link2", r"'arm7_\nlink2'"),
    ("arm7_\u202elink2", r"'arm7_\u202elink2'"),
], ids=["NUL", "newline", "newline reference", "right-to-left override"])
def test_a_name_with_control_characters_is_refused_and_shown_escaped(tmp_path, written,
                                                                       shown):
    model = arm7_with(tmp_path, LINK2, f'<link name="{written}">')
    message = refusal(scenario_of(model))
    assert (f"line {line_of(LINK2)}, link {shown} <link name>: {shown} holds a" in message
            and "names are printed and typed" in message), message
    assert message.isprintable(), message


@pytest.mark.parametrize("task_changes, what", [
    ({"objects": [[0.5, 0.0, 0.3], [0.02, 0.0, 0.1]], "targets": [0, 1, 0]},
     "scenario.task.objects[1] (0.02, 0.00, 0.10) m is inside"),
    ({"x_range": [0.0, 0.6], "z_range": [0.05, 0.5]},
     "scenario.task.x_range, y_range and z_range (where the objects are drawn) reaches into"),
], ids=["given object", "drawn region"])
def test_objects_inside_the_arms_pedestal_are_refused(task_changes, what):
    message = refusal(scenario_of(ARM7, **task_changes))
    assert (f"{what} the robot's own geometry: link 'arm7_base' <collision 'pedestal'> (a "
            "cylinder of radius 0.085 m, length 0.14 m) of scenario.robot.model_file" in message
            ), message


def test_the_pedestal_stands_where_the_base_pose_puts_it():
    scenario = scenario_of(ARM7, objects=[[0.5, 0.0, 0.3], [1.02, 0.0, 0.1]],
                           targets=[0, 1, 0])
    moved = dataclasses.replace(scenario, robot=dataclasses.replace(
        scenario.robot, base_pose=[1.0, 0.0, 0.0, 0.0]))
    assert "scenario.task.objects[0] (0.50, 0.00, 0.30) m is" not in refusal(moved)
    assert "scenario.task.objects[1] (1.02, 0.00, 0.10) m is inside" in refusal(moved)


def test_a_doctype_is_refused_before_any_entity_is_expanded(tmp_path):
    bomb = ('<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY a "aaaaaaaaaa">'
            + "".join(f'<!ENTITY {c} "&{p};&{p};&{p};&{p};&{p};&{p};&{p};&{p};&{p};&{p};">'
                      for p, c in zip("abcdefgh", "bcdefghi")) + "]>\n")
    model = tmp_path / "bomb.urdf"
    model.write_text(bomb + ARM7.read_text().split("?>", 1)[1].replace(
        '<robot name="pbp_arm7"', '<robot name="&i;"'))
    message = refusal(scenario_of(model))
    assert "does not load: line 2: a DOCTYPE (entity declarations)" in message, message


def test_a_file_larger_than_a_model_is_refused_unread(tmp_path):
    model = tmp_path / "huge.urdf"
    text = ARM7.read_text()
    padding = "<!-- " + "x" * MAX_MODEL_FILE_BYTES + " -->\n"
    model.write_text(text.replace("<robot ", padding + "<robot ", 1))
    message = refusal(scenario_of(model))
    assert (f"the file: {model.stat().st_size:,} bytes is larger than a model file may be "
            f"({MAX_MODEL_FILE_BYTES:,} bytes)" in message), message


SDF_ARM = """<?xml version="1.0"?>
<sdf version="1.7">
  <model name="two_joints">
    <link name="base">
      <collision name="post"><pose>0 0 0.1 0 0 0</pose>
        <geometry><cylinder><radius>0.05</radius><length>0.2</length></cylinder></geometry>
      </collision>
    </link>
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
        <limit><lower>-1</lower><upper>1</upper><velocity>1</velocity></limit></axis>
    </joint>
  </model>
</sdf>
"""


def test_an_sdformat_model_is_checked_alike(tmp_path):
    good, looped = tmp_path / "arm.sdf", tmp_path / "looped.sdf"
    good.write_text(SDF_ARM)
    looped.write_text(SDF_ARM.replace("<parent>base</parent>", "<parent>lower</parent>"))
    config = ArmStationConfig(model_file=str(good), base_frame="base", ee_frame="tool")
    make_arm_station(config)
    started = time.monotonic()
    with pytest.raises(ValueError) as error:
        make_arm_station(dataclasses.replace(config, model_file=str(looped)))
    assert time.monotonic() - started < TIME_BOUND
    elbow = SDF_ARM[:SDF_ARM.index('<joint name="elbow"')].count("\n") + 1
    assert (f"ArmStationConfig.model_file '{looped}': line {elbow}, joint 'elbow' <parent>: link "
            "'upper' closes a loop of joints ('upper' -> 'lower' -> 'upper')"
            in str(error.value)), error.value


LOWER_LINK = '<link name="lower">'


@pytest.mark.parametrize("added, ee_frame, message", [
    ('<model name="gripper"><link name="finger"/></model>', "tool",
     "holds 2 models; the station takes one arm"),
    # A link no joint holds: Drake lets it float (a quaternion joint).
    ('<link name="loose"><pose>1 0 0 0 0 0</pose></link>', "loose",
     "ArmStationConfig.ee_frame 'loose' is not downstream of base_frame 'base': its chain "
     "ends at 'loose'"),
    ('<link name="loose"><pose>1 0 0 0 0 0</pose></link>', "tool",
     "WholeBodyDiffIk needs q̇ = v (no quaternion joints)"),
], ids=["nested model", "loose end effector", "loose link"])
def test_an_sdformat_model_that_is_no_single_arm_is_refused(tmp_path, added, ee_frame,
                                                            message):
    model = tmp_path / "arm.sdf"
    model.write_text(SDF_ARM.replace(LOWER_LINK, f"{added}\n    {LOWER_LINK}"))
    config = ArmStationConfig(model_file=str(model), base_frame="base", ee_frame=ee_frame)
    with pytest.raises(ValueError, match=re.escape(message)):
        make_arm_station(config)


@pytest.mark.parametrize("mass, what", [("-2", "-2 kg is negative; a mass is 0 or more"),
                                        ("heavy", "'heavy' is not a finite number")])
def test_an_sdformat_link_s_mass_is_checked(tmp_path, mass, what):
    upper = '<link name="upper"><pose>0 0 0.2 0 0 0</pose>'
    model = tmp_path / "arm.sdf"
    model.write_text(SDF_ARM.replace(upper, f"{upper}<inertial><mass>{mass}</mass></inertial>"))
    config = ArmStationConfig(model_file=str(model), base_frame="base", ee_frame="tool")
    line = SDF_ARM[:SDF_ARM.index(upper)].count("\n") + 1
    with pytest.raises(ValueError, match=re.escape(
            f"'{model}': line {line}, link 'upper' <inertial><mass>: {what}")):
        make_arm_station(config)


def test_an_obstacle_drawn_into_the_pedestal_is_refused_naming_its_seed():
    scenario = scenario_of(ARM7)
    # Obstacles drawn around the base, kept only 0.01 m from its centre.
    task = DynamicObstacles(x_range=[0.5, 0.7], y_range=[-0.25, 0.25], height=0.35,
                            success_distance=0.03, obstacle_count=1, obstacle_radius=0.03,
                            obstacle_height=0.6, obstacle_speed=0.04,
                            obstacle_x_range=[-0.05, 0.05], obstacle_y_range=[-0.05, 0.05],
                            obstacle_spacing=0.01)
    message = refusal(dataclasses.replace(scenario, task=task, seed=3))
    assert ("scenario.task's obstacle 0 (drawn with seed 3 at (" in message
            and "obstacle_radius 0.03 m) reaches into the robot's own geometry: link "
            "'arm7_base' <collision 'foot'> (a cylinder of radius 0.12 m, length 0.02 m)"
            in message), message


def test_what_drake_says_of_the_file_is_shown_escaped(tmp_path):
    # Not a name: Drake's parser refuses the joint type, quoting it.
    model = arm7_with(tmp_path, '<joint name="arm7_joint4" type="revolute">',
                      '<joint name="arm7_joint4" type="revolute&#27;[2J">')
    message = refusal(scenario_of(model))
    assert "does not load: " in message and "\x1b" not in message, message
    assert r"revolute\x1b[2J" in message, message


BOX_BASE = """<?xml version="1.0"?>
<robot name="box_base">
  <link name="base">
    <collision name="block"><origin xyz="0 0 0" rpy="0 0 {yaw}"/>
      <geometry><box size="0.2 0.2 0.2"/></geometry></collision>
  </link>
</robot>
"""


@pytest.mark.parametrize("box_yaw, base_yaw", [(0.785398, 0.0), (0.0, 0.785398)],
                         ids=["box turned", "base turned"])
def test_a_turned_base_is_measured_as_turned(tmp_path, box_yaw, base_yaw):
    # A 0.2 m cube turned 45 degrees about z: its corners reach 0.141 m along x, while
    # (0.1, 0.1) is 0.141 m from its centre along a face's normal, outside its 0.1 m.
    model = tmp_path / "box.urdf"
    model.write_text(BOX_BASE.format(yaw=box_yaw))
    config = ArmStationConfig(model_file=str(model), base_frame="base", ee_frame="base",
                              base_pose=[0.0, 0.0, 0.0, base_yaw])
    check_clear_of_base(config, [("outside", [0.1, 0.1, 0.0], [0.1, 0.1, 0.0])])
    with pytest.raises(ValueError, match=r"^inside is inside the robot's own geometry: link "
                       r"'base' <collision 'block'> \(a box of sides 0.2 x 0.2 x 0.2 m\)"):
        check_clear_of_base(config, [("inside", [0.13, 0.0, 0.0], [0.13, 0.0, 0.0])])


def test_a_sphere_a_welded_link_and_an_sdformat_base_are_measured_too(tmp_path):
    model = tmp_path / "base.urdf"
    model.write_text(BOX_BASE.format(yaw=0.0).replace(
        '<box size="0.2 0.2 0.2"/>', '<sphere radius="0.1"/>').replace("</robot>", """\
  <link name="plate">
    <collision name="slab"><geometry><box size="0.1 0.1 0.02"/></geometry></collision>
  </link>
  <joint name="weld" type="fixed"><parent link="base"/><child link="plate"/>
    <origin xyz="0.5 0 0"/></joint>
</robot>"""))
    config = ArmStationConfig(model_file=str(model), base_frame="base", ee_frame="base")
    # (0.08, 0.08) is 0.113 m from the sphere's centre; (0.3, 0) between sphere and plate.
    check_clear_of_base(config, [("outside", [0.08, 0.08, 0.0], [0.08, 0.08, 0.0]),
                                 ("between", [0.3, 0.0, 0.0], [0.3, 0.0, 0.0])])
    with pytest.raises(ValueError, match=r"^near is inside the robot's own geometry: link "
                       r"'base' <collision 'block'> \(a sphere of radius 0.1 m\)"):
        check_clear_of_base(config, [("near", [0.07, 0.0, 0.0], [0.07, 0.0, 0.0])])
    with pytest.raises(ValueError, match=r"^on is inside the robot's own geometry: link "
                       r"'plate' <collision 'slab'> \(a box of sides 0.1 x 0.1 x 0.02 m\)"):
        check_clear_of_base(config, [("on", [0.52, 0.0, 0.0], [0.52, 0.0, 0.0])])
    sdf = tmp_path / "arm.sdf"
    sdf.write_text(SDF_ARM)
    config = ArmStationConfig(model_file=str(sdf), base_frame="base", ee_frame="tool")
    check_clear_of_base(config, [("beside", [0.1, 0.0, 0.1], [0.1, 0.0, 0.1])])
    with pytest.raises(ValueError, match=r"^above is inside the robot's own geometry: link "
                       r"'base' <collision 'post'> \(a cylinder of radius 0.05 m, length 0.2 m\)"):
        check_clear_of_base(config, [("above", [0.0, 0.0, 0.15], [0.0, 0.0, 0.15])])
