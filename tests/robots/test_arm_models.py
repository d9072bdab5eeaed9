"""Our models of the Franka Panda and the KUKA iiwa 14 (models/make_arm_models.py writes
them): the files are the generator's, their kinematics and limits the published ones, and
the shipped scenarios' ready configurations, stated as tool poses, are solved by inverse
kinematics within the joints' limits."""

import dataclasses
import importlib.util
import math
import pathlib

import numpy as np
import pytest
from pydrake.manipulation import get_iiwa_max_joint_velocities
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

from pbp_drake.builder import run_task
from pbp_drake.commands.task_runs import why_failed
from pbp_drake.robots import (
    arm_ready_ee_state, arm_station, arm_station_plant, make_arm_station)
from pbp_drake.robots.arm_station_config import ToolPose
from pbp_drake.robots.hsr_diff_ik import WholeBodyDiffIk
from pbp_drake.robots.hsr_model import configure_parser
from pbp_drake.scenarios import load_scenario_file

REPO = pathlib.Path(__file__).resolve().parents[2]


def generator():
    spec = importlib.util.spec_from_file_location("make_arm_models",
                                                  REPO / "models" / "make_arm_models.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def plant_of(name):
    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    configure_parser(parser)
    file = {"panda": "panda/pbp_panda.urdf", "iiwa14": "iiwa/pbp_iiwa14.urdf"}[name]
    parser.AddModels(url=f"package://pbp_drake_models/{file}")
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(f"{name}_link0"))
    plant.Finalize()
    return plant


def joints(plant, name):
    return [plant.GetJointByName(f"{name}_joint{index}") for index in range(1, 8)]


def flange(plant, name, q, length):
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, q)
    return plant.GetFrameByName(f"{name}_link7").CalcPoseInWorld(context).multiply(
        [0.0, 0.0, length])


def test_the_model_files_are_what_the_generator_writes():
    for path, text in generator().models().items():
        assert path.read_text() == text, f"{path.name}: run python models/make_arm_models.py"


def test_the_panda_has_franka_s_kinematics_and_limits():
    plant = plant_of("panda")
    np.testing.assert_allclose(flange(plant, "panda", np.zeros(7), 0.107),
                               [0.088, 0.0, 0.926], atol=1e-9)
    ready = [0, -math.pi / 4, 0, -3 * math.pi / 4, 0, math.pi / 2, math.pi / 4]
    np.testing.assert_allclose(flange(plant, "panda", ready, 0.107), [0.3069, 0.0, 0.5903],
                               atol=1e-4)
    limits = np.array([[j.position_lower_limits()[0], j.position_upper_limits()[0],
                        j.velocity_upper_limits()[0], j.acceleration_upper_limits()[0]]
                       for j in joints(plant, "panda")])
    np.testing.assert_array_equal(limits[:, 1], [2.8973, 1.7628, 2.8973, -0.0698, 2.8973,
                                                 3.7525, 2.8973])
    np.testing.assert_array_equal(limits[:, 0], [-2.8973, -1.7628, -2.8973, -3.0718, -2.8973,
                                                 -0.0175, -2.8973])
    np.testing.assert_array_equal(limits[:, 2], [2.175] * 4 + [2.61] * 3)
    np.testing.assert_array_equal(limits[:, 3], [15, 7.5, 10, 12.5, 15, 20, 20])


def test_the_iiwa_has_kuka_s_segments_and_limits():
    plant = plant_of("iiwa14")
    context = plant.CreateDefaultContext()
    heights = [plant.GetJointByName(f"iiwa14_joint{index}").frame_on_child()
               .CalcPoseInWorld(context).translation()[2] for index in (2, 4, 6)]
    np.testing.assert_allclose(heights, [0.36, 0.78, 1.18], atol=1e-9)
    np.testing.assert_allclose(flange(plant, "iiwa14", np.zeros(7), 0.045), [0, 0, 1.306],
                               atol=1e-9)
    upper = [j.position_upper_limits()[0] for j in joints(plant, "iiwa14")]
    np.testing.assert_allclose(np.degrees(upper), [170, 120, 170, 120, 170, 120, 175])
    velocity = [j.velocity_upper_limits()[0] for j in joints(plant, "iiwa14")]
    np.testing.assert_allclose(velocity, get_iiwa_max_joint_velocities(), atol=1e-6)


@pytest.mark.parametrize("arm", ["panda", "iiwa"])
def test_the_ready_tool_pose_is_where_the_station_starts(arm):
    config = load_scenario_file(REPO / "diagrams" / f"{arm}_reach.yaml"
                                ).scenario.robot.station_config()
    station = make_arm_station(config)
    X_WE = config.ready_tool_pose.transform()
    plant = arm_station_plant(station)
    context = station.CreateDefaultContext()
    q = plant.GetPositions(plant.GetMyContextFromRoot(context)) if station.HasSubsystemNamed(
        "plant") else np.array(station.GetOutputPort("state").Eval(context))[:7]
    assert np.all(q >= plant.GetPositionLowerLimits())
    assert np.all(q <= plant.GetPositionUpperLimits())
    np.testing.assert_allclose(arm_ready_ee_state(config)[:3], X_WE.translation(), atol=1e-4)


def test_a_tool_pose_out_of_reach_is_refused_naming_the_field():
    config = load_scenario_file(REPO / "diagrams" / "panda_reach.yaml"
                                ).scenario.robot.station_config()
    far = ToolPose(position=[2.0, 0.0, 0.4], rpy_degrees=[0.0, 90.0, 0.0])
    with pytest.raises(ValueError, match="ready_tool_pose: ee_frame 'panda_ee' cannot stand"):
        arm_ready_ee_state(dataclasses.replace(config, ready_tool_pose=far))


def _panda_trial(method, seed):
    """diagrams/panda_reach.yaml's scenario run by `method` on `seed`."""
    return dataclasses.replace(load_scenario_file(REPO / "diagrams" / "panda_reach.yaml").scenario,
                               method=method, seed=seed)


def _with_robot(scenario, **fields):
    """`scenario` with its robot's `fields` replaced."""
    return dataclasses.replace(scenario, robot=dataclasses.replace(scenario.robot, **fields))


@pytest.mark.slow
def test_the_panda_s_limit_margin_keeps_a_joint_from_stalling_on_its_limit():
    # PBP-Alt's tuning seed 87: without the file's limit_margin a joint reaches its limit on
    # the way and the hand creeps short of the target until the time limit.
    scenario = _panda_trial("pbp_alternated", 87)
    kept_off = run_task(scenario)
    stalled = run_task(_with_robot(scenario, limit_margin=0.0))
    assert kept_off.success and kept_off.task_time < 20.0
    assert not stalled.success
    # The failed run's line names the joints that hold the hand there.
    assert kept_off.joints_at_limits == [] and stalled.joints_at_limits == [
        "panda_joint5", "panda_joint6"]
    assert why_failed(stalled, scenario).endswith(
        "; at a joint limit: panda_joint5, panda_joint6")


@pytest.mark.slow
def test_the_panda_passes_its_shoulder_singularity_without_a_jump():
    # Teleop's tuning seed 7 brings the upper arm upright (joint 2 near 0), where joints 1
    # and 3 turn about one axis: without the file's singular_margin the diff IK spins
    # that pair until joint 1 meets its limit and the hand jumps (beyond the hand's speed
    # limit of 0.2 m/s: 0.28 m/s with the joints braking toward their limits, 0.9 without).
    scenario = _panda_trial("teleop", 7)
    damped = run_task(scenario)
    undamped = run_task(_with_robot(scenario, singular_margin=0.0))
    assert damped.success and damped.peak_hand_speed < 0.2
    assert undamped.peak_hand_speed > 0.25


@pytest.mark.slow
def test_a_joint_brakes_toward_its_limit_and_the_hand_does_not_jump(monkeypatch):
    # PBP-Cont's tuning seed 53: joint 1 runs into its limit at over 1 rad/s; stopped there
    # in one diff IK step, it threw the hand 2.5 cm sideways in one tick (0.84 m/s).
    scenario = _panda_trial("pbp_continuous", 53)
    braked = run_task(scenario)
    monkeypatch.setattr(arm_station, "WholeBodyDiffIk", lambda *arguments, **options: (
        WholeBodyDiffIk(*arguments, **{**options, "brake_at_limits": False})))
    unbraked = run_task(scenario)
    assert braked.success and braked.peak_hand_speed < 0.35
    assert unbraked.peak_hand_speed > 0.8
