"""Where the page's camera looks from: `overview` (Meshcat's own camera, which the person
can orbit) or `robot`, above and behind the HSR's head, looking where the base faces, as
the paper's participants saw the robot."""

import numpy as np

from pbp_drake.robots.hsr_station import hsr_station_plant

CAMERAS = ("overview", "robot")

# High above and a little behind the head (metres): the line of sight to the hand passes
# over the head all through a reaching task (tests/console/test_camera.py).
BEHIND = 0.5
ABOVE = 1.5
# The point looked at: ahead of the head and low, the view running from the hand to the
# far objects (the reaching task's are 1.25 m to 2.5 m ahead).
AHEAD = 1.2
TARGET_HEIGHT = 0.3


def behind_head_view(head_position, yaw, behind=BEHIND, above=ABOVE, ahead=AHEAD,
                     target_height=TARGET_HEIGHT):
    """`(camera, target)` in the world frame for a camera `behind` and `above` a head at
    `head_position` (3) on a base facing `yaw` (rad about world z), looking at the point
    `ahead` of the head at `target_height`."""
    head = np.asarray(head_position, dtype=float)
    forward = np.array([np.cos(yaw), np.sin(yaw), 0.0])
    camera = head - behind * forward + np.array([0.0, 0.0, above])
    target = head + ahead * forward
    target[2] = target_height
    return camera, target


class RobotCamera:
    """Keeps `meshcat`'s camera above and behind the head of the HSR `station` (dynamic or
    kinematic): `update(root_context)` reads its `state` and sets the camera
    (`behind_head_view`). Use from Meshcat's thread."""

    def __init__(self, meshcat, station):
        self._meshcat = meshcat
        self._station = station
        self._state_port = station.GetOutputPort("state")
        self._plant = hsr_station_plant(station)
        self._plant_context = self._plant.CreateDefaultContext()
        self._head = self._plant.GetBodyByName("head_link")
        self._base = self._plant.GetBodyByName("base_link")

    def update(self, root_context):
        context = self._plant_context
        self._plant.SetPositionsAndVelocities(context, self._state_port.Eval(
            self._station.GetMyContextFromRoot(root_context)))
        head = self._head.EvalPoseInWorld(context).translation()
        rotation = self._base.EvalPoseInWorld(context).rotation().matrix()
        yaw = float(np.arctan2(rotation[1, 0], rotation[0, 0]))
        camera, target = behind_head_view(head, yaw)
        self._meshcat.SetCameraPose(camera, target)
