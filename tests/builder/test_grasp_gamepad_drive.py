"""An injected-message test drives the 6-axis gamepad path through a
whole grasp. A page on Meshcat's websocket (`foreign_page.ForeignPage`, the one page
connected) sends the gamepad states a browser sends; a small driver reads the hand's pose
and the target from the diagram each tick and pushes the sticks, triggers and shoulders
towards the target's grasp pose, through the `PoseGamepadOperator` of the grasp diagram,
until the task monitor declares success. Each message is awaited in Meshcat before the
simulator steps on, so the run is in lock step with the sends (Meshcat is used only from
the test's thread)."""

import dataclasses
import time

import numpy as np
import pytest
from foreign_page import ForeignPage
from pydrake.systems.analysis import SimulatorStatus

from pbp_drake.builder import build_diagram, run_task
from pbp_drake.core import quaternion
from pbp_drake.core.operator_frame import hand_axes, operator_frame
from pbp_drake.scenarios import Gamepad, load_scenario_file, resolve
from pbp_drake.systems.operators.pose_gamepad_operator import (
    LEFT_SHOULDER, LEFT_STICK_X, LEFT_STICK_Y, LEFT_TRIGGER, RIGHT_SHOULDER, RIGHT_STICK_X,
    RIGHT_STICK_Y, RIGHT_TRIGGER)

pytestmark = pytest.mark.slow

DEAD_ZONE = 0.15
# Full push until this close (m, rad), proportional below: the hand slows into the grasp.
NEAR, NEAR_ANGLE = 0.08, 0.25
# The shoulders are digital: roll only while the roll error is above this (rad).
ROLL_THRESHOLD = 0.04


def past_dead_zone(unit):
    """The deflection that the operator's dead zone turns back into `unit` (in [0, 1])."""
    return 0.0 if unit <= 1e-3 else DEAD_ZONE + min(unit, 1.0) * (1.0 - DEAD_ZONE)


def stick(first, second):
    """Stick axes for the wanted unit inputs `(first, second)` (radial dead zone)."""
    magnitude = np.hypot(first, second)
    if magnitude <= 1e-3:
        return 0.0, 0.0
    scale = past_dead_zone(magnitude) / magnitude
    return first * scale, second * scale


def gamepad_towards(hand, goal):
    """Axes (4) and buttons (17) that steer a hand `[p, q]` to the grasp pose `goal`."""
    position, orientation = hand[:3], hand[3:7]
    forward, left, up = operator_frame(orientation)
    error = goal[:3] - position
    push = error / max(np.linalg.norm(error), NEAR)  # unit far away, smaller up close
    # Rotation: the world rotation vector from the hand to the grasp, split over the
    # operator's three rotation axes (world up, left, the approach axis z_H).
    turn = quaternion.log_map(quaternion.multiply(goal[3:7], quaternion.conjugate(
        orientation)))
    approach = hand_axes(orientation)[:, 2]
    yaw, pitch, roll = np.linalg.lstsq(np.column_stack([up, left, approach]), turn,
                                       rcond=None)[0]
    axes = [0.0] * 4
    buttons = [0.0] * 17
    # Browser stick y is down: pushing up (forward, pitch down) is a negative y.
    left_x, left_y = stick(-push @ left, -push @ forward)
    axes[LEFT_STICK_X], axes[LEFT_STICK_Y] = left_x, left_y
    lift = push @ up
    buttons[RIGHT_TRIGGER if lift > 0 else LEFT_TRIGGER] = past_dead_zone(abs(lift))
    right_x, right_y = stick(-yaw / max(abs(yaw), abs(pitch), NEAR_ANGLE),
                             -pitch / max(abs(yaw), abs(pitch), NEAR_ANGLE))
    axes[RIGHT_STICK_X], axes[RIGHT_STICK_Y] = right_x, right_y
    if abs(roll) > ROLL_THRESHOLD:
        buttons[RIGHT_SHOULDER if roll > 0 else LEFT_SHOULDER] = 1.0
    # What a page sends is float32-exact: round so Meshcat's copy compares equal.
    return ([float(np.float32(a)) for a in axes], [float(np.float32(b)) for b in buttons])


class GamepadDriver:
    """Each tick: read the hand pose and the target in the diagram, send the gamepad state
    that steers towards the target's grasp pose, wait until Meshcat holds it, step."""

    def __init__(self, meshcat, diagram, grasps, period, assist):
        self.meshcat, self.grasps, self.period = meshcat, grasps, period
        self.assist = assist
        self.sample = diagram.GetSubsystemByName("hand_pose_sample")
        self.monitor = diagram.GetSubsystemByName("task_monitor")
        self.estimator = diagram.GetSubsystemByName("goal_estimator")
        self.page = ForeignPage(meshcat.port(), origin=meshcat.web_url())
        self.sent = 0

    def advance(self, simulator, end_time):
        root = simulator.get_context()
        while root.get_time() < end_time - 1e-9:
            hand = self.sample.get_output_port().Eval(self.sample.GetMyContextFromRoot(root))
            target = self.monitor.get_target_output_port().Eval(
                self.monitor.GetMyContextFromRoot(root))
            index = int(target[3])
            goal = np.concatenate([self.grasps.grasp_positions[index],
                                   self.grasps.grasp_orientations[index]])
            selected = int(self.estimator.get_selected_goal_output_port().Eval(
                self.estimator.GetMyContextFromRoot(root))[0])
            if self.assist and selected == index:
                # PBP: the DMP already heads for the target's grasp; let go so it carries on.
                self.send([0.0] * 4, [0.0] * 17)
            else:
                self.send(*gamepad_towards(np.asarray(hand), goal))
            if advance_one(simulator, root.get_time() + self.period):
                return True
        return False

    def send(self, axes, buttons):
        self.page.send({"type": "gamepad", "name": "",
                        "gamepad": {"index": 0, "button_values": buttons, "axes": axes}})
        self.sent += 1
        deadline = time.monotonic() + 5.0
        while not (held(self.meshcat.GetGamepad().axes, axes)
                   and held(self.meshcat.GetGamepad().button_values, buttons)):
            assert time.monotonic() < deadline, "Meshcat did not receive the gamepad state"
            time.sleep(0.001)


def held(received, sent):
    return len(received) == len(sent) and np.allclose(received, sent)


def advance_one(simulator, time_):
    """One tick; True when the task monitor ended the run (success)."""
    return (simulator.AdvanceTo(time_).reason()
            == SimulatorStatus.ReturnReason.kReachedTerminationCondition)


@pytest.fixture(scope="module")
def grasp(repo):
    return load_scenario_file(repo / "diagrams" / "hsr_grasp.yaml").resolved


@pytest.mark.parametrize("method", ["teleop", "pbp_alternated"])
def test_the_gamepad_drives_a_whole_grasp_through_the_page(grasp, meshcat, method):
    resolved = resolve(dataclasses.replace(grasp.scenario, method=method,
                                           operator=Gamepad()))
    diagram = build_diagram(resolved, meshcat)
    driver = GamepadDriver(meshcat, diagram, resolved.scene.grasps,
                           resolved.scenario.control_period, assist=method != "teleop")
    try:
        result = run_task(resolved, meshcat, diagram=diagram, advance=driver.advance)
    finally:
        driver.page.close()
    assert result.success, f"no grasp in {resolved.scenario.duration} s"
    assert result.switches == 2  # the target switched twice on the way, as scheduled
    assert result.task_time < resolved.scenario.duration
    # The person's gamepad drove it: the operator was active, and with PBP-Alt the DMPs
    # carried part of the way (forward along the approach is theirs alone).
    if method == "pbp_alternated":
        # 0.11 on this seed: the estimator reads the gamepad's twist and follows it soon.
        assert 0.05 < result.intervention_ratio < 0.5
    else:
        assert result.intervention_ratio > 0.9
    assert driver.sent >= len(result.times) - 1
