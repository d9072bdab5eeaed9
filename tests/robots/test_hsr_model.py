"""Tests of the primitive-shape HSR model: it loads, has the published joints and
limits, couples the torso to the arm lift, and reaches the whole object region of
the multi-goal reaching task (objects at X 1.25..2.5 m, Y -1.05..1.05 m)."""

import subprocess
import sys

import numpy as np
import pytest
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.solvers import Solve
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from pbp_drake.robots.hsr_model import (
    ACTUATED_JOINT_NAMES,
    ARM_JOINT_NAMES,
    BASE_JOINT_NAMES,
    END_EFFECTOR_FRAME,
    NEUTRAL_ARM_POSITIONS,
    TORSO_JOINT_NAME,
    TORSO_TO_ARM_LIFT_RATIO,
    actuator_name,
    add_hsr,
    models_dir,
)

# Published HSR-B limits (each part's urdf.xacro in Toyota's hsr_description and
# hsrb_description, e.g. urdf/arm_v0/arm.urdf.xacro): lower, upper, max velocity, max effort.
PUBLISHED_LIMITS = {
    "torso_lift_joint": (0.0, 0.345, 0.1, None),  # mimic joint: no actuator
    "arm_lift_joint": (0.0, 0.69, 0.2, 100.0),
    "arm_flex_joint": (-2.62, 0.0, 1.2, 100.0),
    "arm_roll_joint": (-2.09, 3.84, 2.0, 100.0),
    "wrist_flex_joint": (-1.92, 1.22, 1.5, 100.0),
    "wrist_roll_joint": (-1.92, 3.67, 1.5, 100.0),
}

# Objects lie on a surface 0.7 m high (HSR's published grasp range is floor to 0.725 m).
OBJECT_HEIGHT = 0.7
OBJECT_X = (1.25, 1.875, 2.5)
OBJECT_Y = (-1.05, 0.0, 1.05)


def make_hsr(gravity=True):
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.001)
    model = add_hsr(plant)
    if not gravity:
        plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
    plant.Finalize()
    return builder.Build(), plant, model


def neutral_positions(plant, model):
    q = np.zeros(plant.num_positions())
    for name, value in zip(ARM_JOINT_NAMES, NEUTRAL_ARM_POSITIONS):
        q[plant.GetJointByName(name, model).position_start()] = value
    return q


@pytest.fixture(scope="module")
def hsr():
    return make_hsr()


def test_models_dir_holds_the_package():
    assert (models_dir() / "pbp_drake_models" / "package.xml").is_file()


def test_loads_with_actuated_base_and_arm(hsr):
    _, plant, model = hsr
    assert plant.is_finalized()
    assert [plant.GetJointByName(name, model).type_name() for name in BASE_JOINT_NAMES] \
        == ["prismatic", "prismatic", "revolute"]
    # 3 base + torso + 5 arm joints; every one but the (coupled) torso has a motor.
    assert plant.num_positions() == 9
    assert plant.num_actuated_dofs() == len(ACTUATED_JOINT_NAMES) == 8
    motors = [plant.get_joint_actuator(index) for index in plant.GetJointActuatorIndices(model)]
    assert [motor.name() for motor in motors] == [
        actuator_name(name) for name in ACTUATED_JOINT_NAMES]
    assert [motor.joint().name() for motor in motors] == list(ACTUATED_JOINT_NAMES)
    context = plant.CreateDefaultContext()
    assert 30.0 < plant.CalcTotalMass(context) < 40.0  # published sum: 34.8 kg
    plant.GetFrameByName(END_EFFECTOR_FRAME, model)


@pytest.mark.parametrize("name", PUBLISHED_LIMITS)
def test_joint_has_published_limits(hsr, name):
    _, plant, model = hsr
    lower, upper, velocity, effort = PUBLISHED_LIMITS[name]
    joint = plant.GetJointByName(name, model)
    np.testing.assert_allclose(joint.position_lower_limits(), [lower])
    np.testing.assert_allclose(joint.position_upper_limits(), [upper])
    np.testing.assert_allclose(joint.velocity_upper_limits(), [velocity])
    if effort is not None:
        actuator = plant.GetJointActuatorByName(actuator_name(name), model)
        assert actuator.joint().name() == name
        assert actuator.effort_limit() == effort


@pytest.mark.parametrize("name, speed, position_limit", [
    ("base_x_joint", 0.2, 10.0), ("base_y_joint", 0.2, 10.0), ("base_yaw_joint", 1.0, np.inf)])
def test_base_limits_are_in_the_model_file(hsr, name, speed, position_limit):
    # Speeds of HSR's planning software (0.2 m/s, 1.0 rad/s); positions wide, yaw free.
    _, plant, model = hsr
    joint = plant.GetJointByName(name, model)
    np.testing.assert_allclose(joint.velocity_lower_limits(), [-speed])
    np.testing.assert_allclose(joint.velocity_upper_limits(), [speed])
    np.testing.assert_allclose(joint.position_lower_limits(), [-position_limit])
    np.testing.assert_allclose(joint.position_upper_limits(), [position_limit])
    assert plant.GetJointActuatorByName(actuator_name(name), model).effort_limit() > 0


def test_neutral_pose_matches_published_forward_kinematics(hsr):
    _, plant, model = hsr
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, neutral_positions(plant, model))
    X_WPalm = plant.GetFrameByName("hand_palm_link", model).CalcPoseInWorld(context)
    np.testing.assert_allclose(X_WPalm.translation(), [0.2865, 0.078, 0.6731], atol=1e-3)
    # The end effector sits 8 cm in front of the palm and its z axis points forward.
    X_WE = plant.GetFrameByName(END_EFFECTOR_FRAME, model).CalcPoseInWorld(context)
    np.testing.assert_allclose(X_WE.rotation().matrix()[:, 2], [1, 0, 0], atol=1e-2)
    np.testing.assert_allclose(X_WE.translation(), [0.3665, 0.078, 0.6731], atol=1e-3)


def test_torso_follows_arm_lift():
    diagram, plant, model = make_hsr(gravity=False)
    assert plant.num_constraints() >= 1
    torso = plant.GetJointByName(TORSO_JOINT_NAME, model)
    arm_lift = plant.GetJointByName("arm_lift_joint", model)
    simulator = Simulator(diagram)
    context = plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    # Start consistent in position but with only the arm lift moving.
    arm_lift.set_translation(context, 0.3)
    torso.set_translation(context, 0.15)
    arm_lift.set_translation_rate(context, 0.1)
    simulator.AdvanceTo(0.05)
    ratio = 0.5  # published mimic multiplier
    assert torso.get_translation_rate(context) > 0.01
    assert torso.get_translation_rate(context) == pytest.approx(
        ratio * arm_lift.get_translation_rate(context), abs=1e-4)
    assert torso.get_translation(context) == pytest.approx(
        ratio * arm_lift.get_translation(context), abs=1e-4)


def test_end_effector_reaches_the_object_region(hsr):
    diagram, plant, model = hsr
    ee = plant.GetFrameByName(END_EFFECTOR_FRAME, model)
    torso = plant.GetJointByName(TORSO_JOINT_NAME, model).position_start()
    arm_lift = plant.GetJointByName("arm_lift_joint", model).position_start()
    lower = plant.GetPositionLowerLimits()
    upper = plant.GetPositionUpperLimits()
    guess = neutral_positions(plant, model)  # base at the origin, arm neutral
    diagram_context = diagram.CreateDefaultContext()
    context = plant.GetMyMutableContextFromRoot(diagram_context)
    query_port = plant.get_geometry_query_input_port()

    for x in OBJECT_X:
        for y in OBJECT_Y:
            target = np.array([x, y, OBJECT_HEIGHT])
            ik = InverseKinematics(plant, with_joint_limits=True)
            ik.AddPositionConstraint(
                frameB=ee, p_BQ=np.zeros(3), frameA=plant.world_frame(),
                p_AQ_lower=target, p_AQ_upper=target)
            q = ik.q()
            # IK does not know the coupler constraint; impose it explicitly.
            ik.prog().AddLinearEqualityConstraint(
                q[torso] - TORSO_TO_ARM_LIFT_RATIO * q[arm_lift], 0.0)
            result = Solve(ik.prog(), guess)
            assert result.is_success(), f"IK failed for object at {target}"

            q_sol = result.GetSolution(q)
            assert np.all(q_sol >= lower - 1e-6) and np.all(q_sol <= upper + 1e-6)
            assert q_sol[torso] == pytest.approx(0.5 * q_sol[arm_lift], abs=1e-6)
            plant.SetPositions(context, q_sol)
            p_WE = ee.CalcPoseInWorld(context).translation()
            assert np.linalg.norm(p_WE - target) < 0.01, (target, p_WE)
            # The reaching pose found is also free of self-collision.
            query_object = query_port.Eval(context)
            assert not query_object.ComputePointPairPenetration(), target


def test_models_dir_explains_a_missing_package(monkeypatch, tmp_path):
    from pbp_drake.robots import hsr_model

    monkeypatch.setattr(hsr_model, "__file__", str(tmp_path / "pbp_drake/robots/hsr_model.py"))
    with pytest.raises(FileNotFoundError, match="pbp_drake_models"):
        hsr_model.models_dir()


def test_add_hsr_refuses_what_drake_would_abort_on():
    # In a process of its own: where Drake's parser gets them, the interpreter aborts.
    code = """
from pydrake.multibody.plant import MultibodyPlant
from pbp_drake.robots.hsr_model import add_hsr
for plant in (None, "plant"):
    try:
        add_hsr(plant)
    except ValueError as error:
        print(error)
finalized = MultibodyPlant(0.01)
finalized.Finalize()
try:
    add_hsr(finalized)
except ValueError as error:
    print(error)
"""
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stdout.splitlines() == [
        "plant must be a MultibodyPlant, got NoneType",
        "plant must be a MultibodyPlant, got str",
        "plant is finalized: call add_hsr(plant) before plant.Finalize()"]
