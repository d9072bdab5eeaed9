"""The robot camera (`pbp-drake run --camera robot`) shows the work: through Meshcat's camera,
where `RobotCamera` puts it, the hand and the yellow target marker fall inside the page and
no line of sight to them crosses the robot's head, all through a virtual participant's
reaching task; the view it replaced, from behind the head, fails the same check.

Meshcat's camera is a pinhole (three.js' PerspectiveCamera, 75 degrees of vertical field of
view, the browser tests' 1280 x 720 page); the head is its bounding sphere, made from the
model's own shapes, so that a sight line that misses the sphere misses the head.
"""

import dataclasses

import numpy as np
import pytest
from pydrake.geometry import Box, Cylinder, Role
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from pbp_drake.builder import build_diagram, find_system
from pbp_drake.console.camera import RobotCamera, behind_head_view
from pbp_drake.robots.hsr_model import add_hsr
from pbp_drake.robots.hsr_station import hsr_station_plant
from pbp_drake.scenarios import load_scenario_file, resolve
from pbp_drake.systems.ports import Target, position_of
from pbp_drake.systems.visualizers.reach_scene_visualizer import TARGET_LIFT

WIDTH, HEIGHT = 1280, 720
VERTICAL_FIELD_OF_VIEW = np.radians(75.0)  # Meshcat's default camera
MARGIN = 20  # pixels a point must keep from the page's edges
HAND_POINTS = ("hand_palm_link", "hand_ee_link")  # the palm and between the fingertips
# The view `behind_head_view` gave before: behind the head, looking over it.
OLD_VIEW = dict(behind=1.1, above=0.85, ahead=1.4, target_height=0.4)


class CameraRecorder:
    """Stands in for Meshcat: keeps the last camera pose set."""

    pose = None

    def SetCameraPose(self, camera, target):
        self.pose = (np.array(camera, float), np.array(target, float))


def pixel(point, camera, target):
    """Where `point` shows on the page, `(column, row)` from its top left, through a
    camera at `camera` looking at `target` with world +z up; None behind the camera."""
    forward = (target - camera) / np.linalg.norm(target - camera)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    offset = np.asarray(point, float) - camera
    depth = offset @ forward
    if depth <= 0:
        return None
    half_height = np.tan(VERTICAL_FIELD_OF_VIEW / 2.0)
    x = (offset @ right) / depth / (half_height * WIDTH / HEIGHT)
    y = (offset @ up) / depth / half_height
    return np.array([(x + 1.0) / 2.0 * WIDTH, (1.0 - y) / 2.0 * HEIGHT])


def on_the_page(point, camera, target):
    where = pixel(point, camera, target)
    return where is not None and (MARGIN <= where[0] <= WIDTH - MARGIN
                                  and MARGIN <= where[1] <= HEIGHT - MARGIN)


def sight_clears(point, camera, sphere):
    """Whether the segment from `camera` to `point` misses the ball `sphere` (centre,
    radius)."""
    centre, radius = sphere
    segment = np.asarray(point, float) - camera
    along = np.clip((centre - camera) @ segment / (segment @ segment), 0.0, 1.0)
    return np.linalg.norm(camera + along * segment - centre) > radius


def head_bounding_sphere_in_head_frame():
    """`(centre (3), radius)` of a ball holding every shape of the model's head_link."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    add_hsr(plant)
    plant.Finalize()
    inspector = scene_graph.model_inspector()
    frame = plant.GetBodyFrameIdOrThrow(plant.GetBodyByName("head_link").index())
    corners = []
    for geometry in inspector.GetGeometries(frame, Role.kIllustration):
        shape = inspector.GetShape(geometry)
        if isinstance(shape, Box):
            half = np.array([shape.width(), shape.depth(), shape.height()]) / 2.0
        elif isinstance(shape, Cylinder):
            half = np.array([shape.radius(), shape.radius(), shape.length() / 2.0])
        else:
            raise AssertionError(f"the head has a {type(shape).__name__}; bound it here")
        pose = inspector.GetPoseInFrame(geometry)
        for signs in np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T:
            corners.append(pose.multiply(signs * half))
    corners = np.array(corners)
    centre = (corners.min(axis=0) + corners.max(axis=0)) / 2.0
    return centre, float(np.max(np.linalg.norm(corners - centre, axis=1)))


HEAD_SPHERE = head_bounding_sphere_in_head_frame()


class ReachingTask:
    """A virtual participant's reaching task (diagrams/hsr_reach.yaml, `seed`) without a
    page, and what the camera check needs of it at the simulator's time."""

    def __init__(self, repo, seed):
        scenario = load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario
        self.resolved = resolve(dataclasses.replace(scenario, seed=seed))
        self.diagram = build_diagram(self.resolved)
        self.simulator = Simulator(self.diagram)
        self.simulator.Initialize()
        self.station = find_system(self.diagram, "hsr_station")
        self.plant = hsr_station_plant(self.station)
        self.plant_context = self.plant.CreateDefaultContext()
        self.monitor = find_system(self.diagram, "task_monitor")

    def _pose(self, body):
        context = self.simulator.get_context()
        self.plant.SetPositionsAndVelocities(self.plant_context, self.station.GetOutputPort(
            "state").Eval(self.station.GetMyContextFromRoot(context)))
        return self.plant.GetBodyByName(body).EvalPoseInWorld(self.plant_context)

    def hand_points(self):
        return [self._pose(body).translation() for body in HAND_POINTS]

    def head_sphere(self):
        return self._pose("head_link").multiply(HEAD_SPHERE[0]), HEAD_SPHERE[1]

    def head_and_yaw(self):
        head, base = self._pose("head_link"), self._pose("base_link").rotation().matrix()
        return head.translation(), float(np.arctan2(base[1, 0], base[0, 0]))

    def target_marker(self):
        """Where the yellow ball is: above the current target (ReachSceneVisualizer)."""
        target = Target(self.monitor.get_target_output_port().Eval(
            self.monitor.GetMyContextFromRoot(self.simulator.get_context())))
        return position_of(target) + [0.0, 0.0, TARGET_LIFT]

    def markers(self):
        return self.resolved.scene.objects + [0.0, 0.0, TARGET_LIFT]


def hidden_or_off_the_page(points, camera, target, head_sphere):
    return [np.round(point, 3).tolist() for point in points
            if not (on_the_page(point, camera, target)
                    and sight_clears(point, camera, head_sphere))]


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_robot_camera_sees_the_hand_and_the_target_over_the_head_all_through_a_task(
        repo, seed):
    task = ReachingTask(repo, seed)
    recorder = CameraRecorder()
    camera = RobotCamera(recorder, task.station)
    times = []
    context = task.simulator.get_context()
    while context.get_time() < task.resolved.scenario.duration:
        camera.update(context)
        points = [*task.hand_points(), task.target_marker()]
        if times == []:
            points += list(task.markers())  # at the start, every object
        hidden = hidden_or_off_the_page(points, *recorder.pose, task.head_sphere())
        assert hidden == [], f"at {context.get_time():.1f} s the camera does not see {hidden}"
        times.append(context.get_time())
        end = context.get_time() + 0.5
        task.simulator.AdvanceTo(end)
        if context.get_time() < end - 1e-9:
            break  # the task ended: the hand reached the last target
    assert len(times) > 10, f"the task ended after {times[-1]:.1f} s"


def test_the_old_view_from_behind_the_head_hid_the_hand_behind_it(repo):
    task = ReachingTask(repo, 0)
    camera, target = behind_head_view(*task.head_and_yaw(), **OLD_VIEW)
    hidden = hidden_or_off_the_page(task.hand_points(), camera, target, task.head_sphere())
    assert len(hidden) == len(HAND_POINTS)
    # ... though the hand itself was on the page: the head was in the way.
    assert all(on_the_page(point, camera, target) for point in task.hand_points())
