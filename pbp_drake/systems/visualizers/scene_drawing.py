"""Meshcat drawing shared by the scene visualizers: a top-down view, paths, axis triads
and goal clouds.

Meshcat's recordings keep only `SetTransform` and `SetProperty` calls (`SetLine` and
`SetObject` replay their last geometry all along), so a changing path is a fixed pool of
spheres (`PathDots`) or triads (`PathTriads`) moved at each publish, and the path
travelled so far dots shown as it grows (`PathTrail`).
"""

import numpy as np
from pydrake.common.eigen_geometry import Quaternion
from pydrake.geometry import Cylinder, Rgba
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.perception import BaseField, Fields, PointCloud

from pbp_drake.core.scene_framing import resample_by_arc_length

# The camera stands this far above the plane; it is orthographic, so the height does not
# change the picture, only which objects are in front.
CAMERA_HEIGHT = 10.0
# Meshcat's camera turns about its view direction so that its up vector points along world
# +z "as much as possible", which is undefined when it looks straight down: a camera this far
# towards -y has +y up on the page, and its tilt (1e-5 rad) shows nowhere.
CAMERA_SLANT = 1e-4
# A triad's axes x, y, z in pure red, green and blue (a screenshot can find them), and the
# turn that lays a cylinder (along its z) along each axis.
TRIAD_AXES = (("x", Rgba(1.0, 0.0, 0.0, 1.0), RotationMatrix.MakeYRotation(np.pi / 2)),
              ("y", Rgba(0.0, 1.0, 0.0, 1.0), RotationMatrix.MakeXRotation(-np.pi / 2)),
              ("z", Rgba(0.0, 0.0, 1.0, 1.0), RotationMatrix()))


def frame_top_down(meshcat, view):
    """Shows the xy-plane from above in Meshcat, +x to the right and +y up, framed on `view`
    `(xmin, xmax, ymin, ymax)` (`core.scene_framing.page_view`). `SetCameraPose` also sets
    the orbit controls' target to the view's centre, which `Set2dRenderMode` alone does not.
    """
    xmin, xmax, ymin, ymax = view
    cx, cy = (xmin + xmax) / 2.0, (ymin + ymax) / 2.0
    meshcat.Set2dRenderMode(xmin=xmin - cx, xmax=xmax - cx, ymin=ymin - cy, ymax=ymax - cy)
    meshcat.SetCameraPose([cx, cy - CAMERA_SLANT, CAMERA_HEIGHT], [cx, cy, 0.0])


def unit_sphere(longitudes=8, latitudes=6):
    """A unit sphere as a triangle mesh: `(vertices (V, 3), faces (F, 3))`, `latitudes`
    bands of `longitudes` quads (triangles at the poles); its vertices average to 0."""
    polar = np.linspace(0.0, np.pi, latitudes + 1)[1:-1]
    azimuth = np.linspace(0.0, 2.0 * np.pi, longitudes, endpoint=False)
    rings = np.stack([np.outer(np.sin(polar), np.cos(azimuth)),
                      np.outer(np.sin(polar), np.sin(azimuth)),
                      np.outer(np.cos(polar), np.ones(longitudes))], axis=-1)
    vertices = np.vstack([[0.0, 0.0, 1.0], rings.reshape(-1, 3), [0.0, 0.0, -1.0]])
    column = np.arange(longitudes)
    following = (column + 1) % longitudes
    south = len(vertices) - 1
    faces = [np.stack([np.zeros_like(column), 1 + column, 1 + following], axis=1)]
    for band in range(latitudes - 2):
        upper, lower = 1 + band * longitudes, 1 + (band + 1) * longitudes
        faces.append(np.stack([upper + column, lower + column, upper + following], axis=1))
        faces.append(np.stack([upper + following, lower + column, lower + following], axis=1))
    last = 1 + (latitudes - 2) * longitudes
    faces.append(np.stack([last + column, np.full_like(column, south), last + following],
                          axis=1))
    return vertices, np.concatenate(faces)


# A dot: a sphere of 80 triangles, as round at a dot's few pixels as Meshcat's own `Sphere`,
# which has 760 (paths of those were slow to draw in a page rendered in software).
DOT_VERTICES, DOT_FACES = unit_sphere()


def spheres_mesh(centres, radius):
    """Spheres of `radius` at `centres` `(N, 3)` as one triangle mesh, as
    `Meshcat.SetTriangleMesh` takes it: `(vertices (3, N V), faces (3, N F))`."""
    centres = np.asarray(centres, dtype=float)
    vertices = centres[:, None, :] + radius * DOT_VERTICES[None]
    faces = np.arange(len(centres))[:, None, None] * len(DOT_VERTICES) + DOT_FACES[None]
    return vertices.reshape(-1, 3).T, faces.reshape(-1, 3).T.astype(np.int32)


def add_dots(meshcat, paths, radius, colour):
    """A dot of `radius` at each of `paths`, centred on its origin (`spheres_mesh`)."""
    vertices, faces = spheres_mesh(np.zeros((1, 3)), radius)
    for path in paths:
        meshcat.SetTriangleMesh(path, vertices, faces, colour)


class Visibility:
    """A Meshcat path's `visible`, sent only when it changes: at each publish a page would
    otherwise get the same value again, and a recording a key. What was sent is kept here,
    not in a Drake context: `forget` where the scene is drawn again (the next `show` sends
    whatever it is: a recording's first key), and one simulation at a time may use it."""

    def __init__(self, path):
        self.path = path
        self._shown = None

    def forget(self):
        self._shown = None

    def show(self, meshcat, shown, time=None):
        shown = bool(shown)
        if shown != self._shown:
            self._shown = shown
            meshcat.SetProperty(self.path, "visible", shown, time)


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
        add_dots(meshcat, [f"{self.root}/{index}" for index in range(self._count)],
                 self._radius, self._colour)

    def show(self, meshcat, path, time=None, lift=0.0):
        """Spreads the spheres along the polyline `path` `(N, 2 or 3)`, raised by `lift` in z
        (positions only: a recording keeps half of what `SetTransform` records)."""
        path = np.atleast_2d(np.asarray(path, dtype=float))
        points = np.zeros((self._count, 3))
        points[:, :path.shape[1]] = resample_by_arc_length(path, self._count)[:, :3]
        points[:, 2] += lift
        for index, point in enumerate(points):
            meshcat.SetProperty(f"{self.root}/{index}", "position", point.tolist(), time)


class PathTrail:
    """The path travelled so far, drawn as it grows: dots of `radius` under the Meshcat path
    `root`, `spacing` apart along it, each shown once the path reaches it. With `time`
    (`time_in_recording`), a replay at time t shows the trail up to t only.

    Hundreds of spheres keep a software-rendered page busy for seconds, so the trail is few
    objects: the newest `piece` dots are spheres of their own (`root/dots/i`); the next dot
    first turns them into one mesh (`root/pieces/n`), hidden in a recording until it is
    made, and the spheres are used again. After `pieces` pieces the spacing doubles for the
    ones to come, so a path however long is a few dozen objects. A moved sphere's old
    position is keyed again at the previous `extend`'s time, so a replay jumps it rather
    than slides it. What is drawn is kept here, not in a Drake context: `draw` starts the
    trail again, and one simulation at a time may use it."""

    def __init__(self, root, radius, colour, spacing, piece=20, pieces=20):
        self.root = root
        self._radius = float(radius)
        self._colour = colour
        self._first_spacing = float(spacing)
        self._piece = max(2, int(piece))
        self._pieces_per_spacing = max(1, int(pieces))
        self._positions = [None] * self._piece  # where each sphere was last put
        # Meshes made under root/pieces, each path used once (a replay shows earlier runs').
        self._made = 0
        self._restart(None)

    def _restart(self, time):
        self._dots = []  # the placed dots not yet in a piece, in order along the path
        self._last = None  # the last placed dot
        self._pieces = []  # this trail's pieces
        self._spacing = self._first_spacing
        self._draw_time = self._last_time = time

    def draw(self, meshcat, time=None):
        """Adds the spheres, hidden, hides an earlier trail's pieces, and starts the trail
        again. Call at the start of a recording with its `time`, so that a replay hides
        each dot until it is placed."""
        for path in self._pieces:
            meshcat.SetProperty(path, "visible", False, time)
        self._restart(time)
        paths = [f"{self.root}/dots/{index}" for index in range(self._piece)]
        add_dots(meshcat, paths, self._radius, self._colour)
        for path in paths:
            meshcat.SetProperty(path, "visible", False, time)

    def extend(self, meshcat, point, time=None):
        """Extends the trail to `point` (3): dots `spacing` apart on the straight line from
        the last dot to it (a robot goes several spacings between two publishes), all
        shown at `time`; the first call places the first dot at `point` itself."""
        point = np.asarray(point, dtype=float)
        if self._last is None:
            self._place(meshcat, point, time)
        while (gap := np.linalg.norm(point - self._last)) >= self._spacing:
            self._place(meshcat, self._last + (point - self._last) * (self._spacing / gap),
                        time)
        self._last_time = time

    def _place(self, meshcat, point, time):
        if len(self._dots) == self._piece:
            self._make_piece(meshcat, time)
        index = len(self._dots)
        self._dots.append(point)
        self._last = point
        path = f"{self.root}/dots/{index}"
        previous = self._positions[index]
        if previous is not None and time is not None and self._last_time is not None:
            meshcat.SetProperty(path, "position", previous.tolist(), self._last_time)
        meshcat.SetProperty(path, "position", point.tolist(), time)
        meshcat.SetProperty(path, "visible", True, time)
        self._positions[index] = point

    def _make_piece(self, meshcat, time):
        """The placed spheres become one mesh, shown at `time`, and are hidden then."""
        path = f"{self.root}/pieces/{self._made}"
        self._made += 1
        self._pieces.append(path)
        meshcat.SetTriangleMesh(path, *spheres_mesh(self._dots, self._radius), self._colour)
        if time is not None and self._draw_time is not None:
            meshcat.SetProperty(path, "visible", False, self._draw_time)
        meshcat.SetProperty(path, "visible", True, time)
        for index in range(self._piece):
            meshcat.SetProperty(f"{self.root}/dots/{index}", "visible", False, time)
        self._dots = []
        if len(self._pieces) % self._pieces_per_spacing == 0:
            self._spacing *= 2.0


# The goal cloud's colours: a goal of no probability grey, the most probable one blue.
UNLIKELY_RGB = np.array([150.0, 150.0, 150.0])
LIKELY_RGB = np.array([25.0, 75.0, 255.0])
# A page rebuilds the whole cloud each time it is sent (Meshcat sends objects whole): at
# most this many points a second keep a page in software rendering in step with 10,000
# goals (sent every 0.25 s, its status fell up to 2 s behind).
CLOUD_POINTS_PER_SECOND = 4000


def cloud_point_size(points, largest):
    """A point size (m) for a cloud of `points` `(K, 3)`: `largest`, or for many points
    spread over the floor 0.6 of their typical spacing (the side of the floor area per
    point), so that neighbours stay apart; at least a fifth of `largest`."""
    points = np.asarray(points, dtype=float)
    extent = np.ptp(points[:, :2], axis=0)
    spacing = np.sqrt(extent[0] * extent[1] / len(points)) if extent.all() else np.inf
    return float(np.clip(0.6 * spacing, 0.2 * largest, largest))


class GoalCloud:
    """K goals drawn as one Meshcat point cloud at `root`, each point coloured by its goal's
    probability relative to the most probable goal's, from grey (`UNLIKELY_RGB`) to blue
    (`LIKELY_RGB`), `cloud_point_size(points, largest_point_size)` wide. `show` sends the
    cloud again only when a colour (a byte) changed. What was sent is kept here, not in a
    Drake context: `restart` forgets it, and one simulation at a time may use it."""

    def __init__(self, root, points, largest_point_size):
        self.root = root
        points = np.asarray(points, dtype=float)
        self._cloud = PointCloud(len(points), Fields(BaseField.kXYZs | BaseField.kRGBs))
        self._cloud.mutable_xyzs()[:] = points.T
        self._point_size = cloud_point_size(points, largest_point_size)
        self._sent = None  # the colours last sent, (3, K) bytes

    def period(self, shortest):
        """How often (s) to offer the cloud new colours: every `shortest` seconds, or less
        often for so many points that it would exceed `CLOUD_POINTS_PER_SECOND`."""
        return max(float(shortest), self._cloud.size() / CLOUD_POINTS_PER_SECOND)

    def restart(self):
        """Forgets what was sent (the page's scene was deleted): the next `show` sends."""
        self._sent = None

    def show(self, meshcat, probabilities=None):
        """Colours the points by `probabilities` (K; None: every goal equally likely, blue)
        and sends the cloud if it was not sent since `restart` or a colour changed."""
        probabilities = (np.ones(self._cloud.size()) if probabilities is None
                         else np.asarray(probabilities, dtype=float))
        largest = probabilities.max()
        share = probabilities / largest if largest > 0 else np.ones_like(probabilities)
        colours = np.rint(UNLIKELY_RGB[:, None] + (LIKELY_RGB - UNLIKELY_RGB)[:, None]
                          * np.clip(share, 0.0, 1.0)).astype(np.uint8)
        if self._sent is not None and np.array_equal(colours, self._sent):
            return
        self._cloud.mutable_rgbs()[:] = colours
        meshcat.SetObject(self.root, self._cloud, self._point_size)
        self._sent = colours


def pose_transform(pose):
    """The `RigidTransform` of a pose `[x, y, z, qw, qx, qy, qz]` (a `GoalPose` row)."""
    pose = np.asarray(pose, dtype=float)
    quaternion = pose[3:7] / np.linalg.norm(pose[3:7])
    return RigidTransform(Quaternion(quaternion), pose[:3])


def draw_triad(meshcat, path, pose=None, length=0.1, radius=0.005, opacity=1.0):
    """Adds an axis triad at Meshcat `path`: three cylinders from its origin along its x, y
    and z, red, green and blue, `length` long. With `pose` (`[x, y, z, qw, qx, qy, qz]`)
    the triad is placed there; `SetTransform(path, ...)` moves it later."""
    for axis, colour, rotation in TRIAD_AXES:
        shade = Rgba(colour.r(), colour.g(), colour.b(), opacity)
        meshcat.SetObject(f"{path}/{axis}", Cylinder(radius, length), shade)
        # The cylinder is centred on its origin: shift it half its length along the axis.
        meshcat.SetTransform(f"{path}/{axis}", RigidTransform(
            rotation, rotation.multiply(np.array([0.0, 0.0, length / 2.0]))))
    if pose is not None:
        meshcat.SetTransform(path, pose_transform(pose))


class PathTriads:
    """A path of poses drawn as `count` triads under the Meshcat path `root`, evenly spaced
    along its positions; `show` moves and turns them, with `time` so that a recording
    replays them (one position and one quaternion track a triad)."""

    def __init__(self, root, count, length, radius, opacity=1.0):
        self.root = root
        self._count = int(count)
        self._shape = (float(length), float(radius), float(opacity))

    def draw(self, meshcat):
        """Adds the triads (all at the origin until `show`)."""
        length, radius, opacity = self._shape
        for index in range(self._count):
            draw_triad(meshcat, f"{self.root}/{index}", None, length, radius, opacity)

    def show(self, meshcat, poses, time=None):
        """Places the triads at the poses of `poses` `(N, 7)` nearest to evenly spaced arc
        lengths along it (its first and last included), each with its orientation."""
        poses = np.atleast_2d(np.asarray(poses, dtype=float))
        for index, row in enumerate(_spread(poses, self._count)):
            meshcat.SetTransform(f"{self.root}/{index}", pose_transform(row), time)


def _spread(poses, count):
    """`count` rows of `poses` at evenly spaced arc lengths (by index where it has none)."""
    steps = np.linalg.norm(np.diff(poses[:, :3], axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(steps)])
    if arc[-1] < 1e-9:  # a path standing still: its orientations may still turn
        picks = np.linspace(0, len(poses) - 1, count)
    else:
        picks = np.interp(np.linspace(0.0, arc[-1], count), arc, np.arange(len(poses)))
    return poses[np.round(picks).astype(int)]
