"""Where the page's camera looks from: `overview` (Meshcat's own camera, which the person
can orbit) or `robot`, behind the HSR's head looking where the base faces, as the paper's
participants saw the robot."""

import numpy as np

from pbp_drake.robots.hsr_station import hsr_station_plant

CAMERAS = ("overview", "robot")

# Behind and above the head, looking down past the hand to the shelf: the view of a person
# standing behind the robot (metres).
BEHIND = 1.1
ABOVE = 0.85
AHEAD = 1.4
TARGET_HEIGHT = 0.4


def behind_head_view(head_position, yaw):
    """`(camera, target)` in the world frame for a camera behind a head at `head_position`
    (3) on a base facing `yaw` (rad about world z)."""
    head = np.asarray(head_position, dtype=float)
    forward = np.array([np.cos(yaw), np.sin(yaw), 0.0])
    camera = head - BEHIND * forward + np.array([0.0, 0.0, ABOVE])
    target = head + AHEAD * forward
    target[2] = TARGET_HEIGHT
    return camera, target


class RobotCamera:
    """Keeps `meshcat`'s camera behind the HSR's head: `update(root_context)` reads the
    robot's `state` off `station` (an HSR station inside the diagram whose root context is
    given, dynamic or kinematic), places the head and the base with the station's plant
    and sets the camera. Use from Meshcat's thread."""

    def __init__(self, meshcat, station, head_body="head_link", base_body="base_link"):
        self._meshcat = meshcat
        self._station = station
        self._state_port = station.GetOutputPort("state")
        self._plant = hsr_station_plant(station)
        self._plant_context = self._plant.CreateDefaultContext()
        self._head = self._plant.GetBodyByName(head_body)
        self._base = self._plant.GetBodyByName(base_body)

    def update(self, root_context):
        context = self._plant_context
        self._plant.SetPositionsAndVelocities(context, self._state_port.Eval(
            self._station.GetMyContextFromRoot(root_context)))
        head = self._head.EvalPoseInWorld(context).translation()
        rotation = self._base.EvalPoseInWorld(context).rotation().matrix()
        yaw = float(np.arctan2(rotation[1, 0], rotation[0, 0]))
        camera, target = behind_head_view(head, yaw)
        self._meshcat.SetCameraPose(camera, target)
