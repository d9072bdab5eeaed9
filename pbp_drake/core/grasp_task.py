"""The grasping task: the reach task's scene with a grasp pose per object, in pure NumPy.

Each object is grasped from the side at a yaw or from above at a wrist roll, the hand's
grasp position `grasp_depth` behind the grasp point along the approach axis z_H.
Orientations are unit quaternions (w, x, y, z) mapping the hand frame H (`hand_palm_link`)
to the world. The scene, the frames and the rules: docs/tasks/grasp.md ("Frames and
conventions", "The scene", "Rules")."""

import dataclasses

import numpy as np

from pbp_drake.core.quaternion import angle_between, exp_map, multiply, unit_quaternions
from pbp_drake.core.reach_task import check_object_count, spread_points

APPROACHES = ("side", "top")
# The region the shipped tasks draw from and the HSR reaches (`reach_task.validate_objects`).
HAND_HEIGHTS = (0.0, 1.1)
Z_AXIS = np.array([0.0, 0.0, 1.0])
Y_AXIS = np.array([0.0, 1.0, 0.0])


@dataclasses.dataclass(frozen=True)
class GraspScene:
    """One grasping scene; index i of every array is grasp i, of object i when each object
    has one grasp (`sample_grasp_scene`'s `grasps_per_object`).

    Attributes:
        objects: (M, 3) each cylinder's centre (on its axis, at half its height).
        tables: (M, 3) each table's top-face centre.
        approaches: M strings of APPROACHES.
        approach_angles: (M,) the side grasp's yaw or the top grasp's roll (rad).
        grasp_positions: (M, 3) the hand frame's origin at each grasp.
        grasp_orientations: (M, 4) the hand's orientation at each grasp (w, x, y, z).
        targets: object indices, one per entry of the switch schedule.
    """

    objects: np.ndarray
    tables: np.ndarray
    approaches: tuple
    approach_angles: np.ndarray
    grasp_positions: np.ndarray
    grasp_orientations: np.ndarray
    targets: tuple


def _about(axis, angle):
    return exp_map(np.asarray(axis, dtype=float) * angle)


def side_grasp_orientation(yaw):
    """The hand's quaternion (4,) grasping from the side at `yaw` (rad):
    `Rz(yaw) Ry(90) Rz(180)`. At yaw 0 it is the HSR's hand at the station's start (x_H up,
    y_H along -y: the model's hand_palm_link), so a grasp straight ahead needs no wrist
    roll."""
    return multiply(multiply(_about(Z_AXIS, yaw), _about(Y_AXIS, np.pi / 2)),
                    _about(Z_AXIS, np.pi))


def top_grasp_orientation(roll):
    """The hand's quaternion (4,) grasping from above with wrist `roll` (rad):
    `Ry(180) Rz(roll + 180)`: at roll 0 the start hand pitched down (the arm alone reaches
    every roll in [-90, 90] degrees then; the model's wrist roll range leaves a gap near +50
    degrees for the hand turned half a turn)."""
    return multiply(_about(Y_AXIS, np.pi), _about(Z_AXIS, roll + np.pi))


def approach_direction(orientation):
    """The world direction (3,) of the hand's approach axis z_H for a quaternion (4,)."""
    w, x, y, z = orientation
    return np.array([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)])


def grasp_pose(center, approach, angle, object_height, grasp_depth):
    """`(position (3,), orientation (4,))` of the hand grasping the cylinder centred at
    `center` from `approach` ("side" or "top") at `angle` (yaw or roll, rad)."""
    center = np.asarray(center, dtype=float)
    if approach == "side":
        orientation, point = side_grasp_orientation(angle), center
    elif approach == "top":
        orientation = top_grasp_orientation(angle)
        point = center + [0.0, 0.0, 0.5 * object_height]
    else:
        raise ValueError(f"approach {approach!r} is unknown; use one of {APPROACHES}")
    return point - grasp_depth * approach_direction(orientation), orientation


def sample_grasp_scene(seed, object_count=(2, 4), x_range=(1.25, 2.5), y_range=(-1.05, 1.05),
                       table_height=0.6, table_size=(0.3, 0.3), object_radius=0.03,
                       object_height=0.15, min_separation=0.45,
                       switch_schedule=(0.0, 0.3, 0.6), yaw_range=(-np.pi / 3, np.pi / 3),
                       roll_range=(-np.pi / 2, np.pi / 2), top_probability=0.5,
                       grasp_depth=0.08, grasps_per_object=1):
    """Draws a `GraspScene` from `seed` alone (the same seed, the same scene, for every
    method). Angles in radians; lengths in metres.

    With `grasps_per_object` G > 1 every object has G grasps, each from the side or from
    above as one grasp is drawn, and the scene's index i is grasp i (object `i // G`: its
    centre and table repeat G times in `objects` and `tables`); the targets are grasps, each
    of another object than the one before. G = 1 draws exactly the one-grasp scene."""
    low, high = check_object_count(object_count, switch_schedule)
    diagonal = float(np.hypot(*table_size))
    if min_separation < diagonal:
        raise ValueError(f"min_separation {min_separation} m is less than the tables' "
                         f"diagonal {diagonal:.3f} m: tables could overlap")
    if 2 * object_radius > min(table_size):
        raise ValueError(f"objects of radius {object_radius} m do not fit on tables "
                         f"{list(table_size)} m wide")
    rng = np.random.default_rng(seed)
    count = int(rng.integers(low, high + 1))
    floor = spread_points(rng, count, x_range, y_range, min_separation, "tables")
    approaches = tuple("top" if rng.uniform() < top_probability else "side"
                       for _ in range(count))
    angles = np.array([rng.uniform(*(roll_range if approach == "top" else yaw_range))
                       for approach in approaches])
    tables = np.column_stack([floor, np.full(count, table_height)])
    objects = tables + [0.0, 0.0, 0.5 * object_height]
    targets = [int(rng.integers(count))]
    for _ in switch_schedule[1:]:
        others = [i for i in range(count) if i != targets[-1]]
        targets.append(int(others[rng.integers(len(others))]))
    if grasps_per_object > 1:
        # Drawn after the one-grasp scene's draws: each object's first grasp is the one
        # above, its other G - 1 drawn alike, and each target one of its object's grasps.
        more = grasps_per_object - 1
        extra = [tuple("top" if rng.uniform() < top_probability else "side"
                       for _ in range(more)) for _ in range(count)]
        extra_angles = [np.array([rng.uniform(*(roll_range if a == "top" else yaw_range))
                                  for a in kinds]) for kinds in extra]
        approaches = tuple(a for first, kinds in zip(approaches, extra)
                           for a in (first, *kinds))
        angles = np.concatenate([[first, *more_angles] for first, more_angles
                                 in zip(angles, extra_angles)])
        tables = np.repeat(tables, grasps_per_object, axis=0)
        objects = np.repeat(objects, grasps_per_object, axis=0)
        targets = [target * grasps_per_object + int(rng.integers(grasps_per_object))
                   for target in targets]
    poses = [grasp_pose(center, approach, angle, object_height, grasp_depth)
             for center, approach, angle in zip(objects, approaches, angles)]
    positions = np.array([position for position, _ in poses])
    heights = positions[:, 2]
    bad = np.flatnonzero((heights < HAND_HEIGHTS[0]) | (heights > HAND_HEIGHTS[1]))
    if bad.size:
        raise ValueError(f"object {bad[0]}'s grasp puts the hand at height "
                         f"{heights[bad[0]]:.2f} m, out of the HSR's reach (heights "
                         f"{HAND_HEIGHTS[0]}..{HAND_HEIGHTS[1]} m): lower table_height or "
                         "object_height")
    return GraspScene(objects=objects, tables=tables, approaches=approaches,
                      approach_angles=angles, grasp_positions=positions,
                      grasp_orientations=np.array([orientation for _, orientation in poses]),
                      targets=tuple(targets))


def grasp_errors(position, orientation, grasp_positions, grasp_orientations):
    """`(distances (K,), angles (K,))` from the hand's pose (position (3,), quaternion
    (4,)) to K grasp poses ((K, 3), (K, 4)); angles in [0, pi], antipodal-safe."""
    distances = np.linalg.norm(np.asarray(grasp_positions, float) - position, axis=-1)
    angles = angle_between(np.asarray(orientation, float)[:, np.newaxis],
                           np.asarray(grasp_orientations, float).T)
    return distances, angles


def grasp_success(position, orientation, grasp_position, grasp_orientation,
                  success_distance, success_angle):
    """Whether the hand is within `success_distance` (m) AND `success_angle` (rad) of one
    grasp pose (bounds inclusive)."""
    orientation = unit_quaternions(orientation, "orientation")
    distances, angles = grasp_errors(position, orientation, [grasp_position],
                                     [grasp_orientation])
    return bool(distances[0] <= success_distance and angles[0] <= success_angle)


def grasp_progress(position, orientation, start_position, start_orientation,
                   grasp_position, grasp_orientation, length_per_radian):
    """`1 - e(hand) / e(start)` clipped to [0, 1], `e = |p - g| + L angle(q, q_g)`; 1 when
    the start is the grasp pose itself."""
    def pose_error(p, q):
        distances, angles = grasp_errors(p, q, [grasp_position], [grasp_orientation])
        return float(distances[0] + length_per_radian * angles[0])

    total = pose_error(start_position, start_orientation)
    if total <= 0.0:
        return 1.0
    return float(np.clip(1.0 - pose_error(position, orientation) / total, 0.0, 1.0))
