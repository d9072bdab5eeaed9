"""Meshcat drawing shared by the scene visualizers: a top-down view framed on a 2-D scene, and
paths drawn so that a recording replays them.

Meshcat's recordings (`StartRecording`) keep only `SetTransform` and `SetProperty` calls, as
animation tracks of transforms, positions and visibility; `SetLine` and `SetObject` change the
page at once and a replay shows their last geometry all along. So a path that changes over
time is a fixed pool of small spheres (`PathDots`) whose positions are set at each publish.
"""

import numpy as np
from pydrake.geometry import Sphere

from pbp_drake.core.scene_framing import resample_by_arc_length

# The camera stands this far above the plane; it is orthographic, so the height does not
# change the picture, only which objects are in front.
CAMERA_HEIGHT = 10.0
# Meshcat's camera turns about its view direction so that its up vector points along world
# +z "as much as possible", which is undefined when it looks straight down: a camera this far
# towards -y has +y up on the page, and its tilt (1e-5 rad) shows nowhere.
CAMERA_SLANT = 1e-4


def frame_top_down(meshcat, view):
    """Shows the xy-plane from above in Meshcat, +x to the right and +y up, framed on `view`
    `(xmin, xmax, ymin, ymax)` (see `core.scene_framing.page_view`), with no background, grid
    or axes.

    `Set2dRenderMode` alone sets the orthographic camera and hides the background, grid and
    axes, but the page's orbit controls then turn the camera towards their target (the
    origin): the scene showed tilted and off-centre. `SetCameraPose` sets both the camera's
    position and the controls' target, here the view's centre.
    """
    xmin, xmax, ymin, ymax = view
    cx, cy = (xmin + xmax) / 2.0, (ymin + ymax) / 2.0
    meshcat.Set2dRenderMode(xmin=xmin - cx, xmax=xmax - cx, ymin=ymin - cy, ymax=ymax - cy)
    meshcat.SetCameraPose([cx, cy - CAMERA_SLANT, CAMERA_HEIGHT], [cx, cy, 0.0])


class PathDots:
    """A path drawn as `count` spheres of `radius` under the Meshcat path `root`, evenly
    spaced along it; `show` moves them, with `time` so that a recording replays it."""

    def __init__(self, root, count, radius, colour):
        self.root = root
        self._count = int(count)
        self._radius = float(radius)
        self._colour = colour

    def draw(self, meshcat):
        """Adds the spheres (all at the origin until `show`)."""
        for index in range(self._count):
            meshcat.SetObject(f"{self.root}/{index}", Sphere(self._radius), self._colour)

    def show(self, meshcat, path, time=None, lift=0.0):
        """Spreads the spheres along the polyline `path` `(N, 2 or 3)`, raised by `lift` in z.

        Only positions are set (`SetProperty(..., "position")`): a recording then keeps one
        track a sphere, half of what `SetTransform` records (position and rotation)."""
        path = np.atleast_2d(np.asarray(path, dtype=float))
        points = np.zeros((self._count, 3))
        points[:, :path.shape[1]] = resample_by_arc_length(path, self._count)[:, :3]
        points[:, 2] += lift
        for index, point in enumerate(points):
            meshcat.SetProperty(f"{self.root}/{index}", "position", point.tolist(), time)
