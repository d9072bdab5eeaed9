"""The multi-goal reaching task of the paper (section IV-B.1, docs/tasks/reach.md), in pure
NumPy: its scenes (objects, and the targets that switch, unannounced, at each threshold of
the progress schedule, `reach_progress`), their checks, and the floor angles its operators
share.
"""

import dataclasses

import numpy as np

from pbp_drake.core.coordinates import vector_length


@dataclasses.dataclass(frozen=True)
class ReachScene:
    """Objects `(M, 3)` and the target sequence (object indices, one per schedule entry)."""

    objects: np.ndarray
    targets: tuple


def check_object_count(object_count, switch_schedule):
    """`(min, max)` of `object_count`, refused unless 1 <= min <= max, and min >= 2 when
    the target switches (more than one entry in `switch_schedule`)."""
    low, high = object_count
    if low < 1 or high < low:
        raise ValueError(f"object_count must be [min, max] with 1 <= min <= max, got "
                         f"{list(object_count)}")
    if len(switch_schedule) > 1 and low < 2:
        raise ValueError("target switching needs at least 2 objects: set object_count to "
                         "at least [2, ...] or switch_schedule to [0.0]")
    return low, high


def sample_reach_scene(seed, object_count=(2, 4), x_range=(1.25, 2.5), y_range=(-1.05, 1.05),
                       height=0.7, switch_schedule=(0.0, 0.3, 0.6), min_separation=0.2,
                       z_range=None):
    """Draws a scene from `seed` alone (the same seed, the same scene, for every method).

    Objects closer than `min_separation` (in the floor plane) are redrawn, so that each can
    be told apart. With a `z_range` (low, high) each object's height is drawn in it, after
    everything else (so the rest of the scene is the same as without); else all are at
    `height`.
    """
    low, high = check_object_count(object_count, switch_schedule)
    rng = np.random.default_rng(seed)
    count = int(rng.integers(low, high + 1))
    floor = spread_points(rng, count, x_range, y_range, min_separation, "objects")
    return _scene_on(rng, floor, height, switch_schedule, z_range)


def _scene_on(rng, floor, height, switch_schedule, z_range):
    """The `ReachScene` of objects on the `floor` points (K, 2): the targets drawn, then
    with a `z_range` the heights."""
    count = len(floor)
    objects = np.column_stack([floor, np.full(count, float(height))])
    # The first target, then at each switch another object than the last.
    targets = [int(rng.integers(count))]
    for _ in switch_schedule[1:]:
        other = int(rng.integers(count - 1))
        targets.append(other + (other >= targets[-1]))
    if z_range:
        objects[:, 2] = rng.uniform(*z_range, size=count)
    return ReachScene(objects=objects, targets=tuple(targets))


def spread_points(rng, count, x_range, y_range, min_separation, what, keep_away=(),
                  apart="apart"):
    """`count` floor points `(count, 2)` drawn uniformly in the rectangle, each redrawn (up
    to 1000 times) until it is `min_separation` from those before it and from the floor
    points `keep_away`; `what` and `apart` name them in the error."""
    points = np.empty((count, 2))
    for index in range(count):
        others = np.vstack([np.reshape(keep_away, (-1, 2)), points[:index]])
        for _ in range(1000):
            candidate = np.array([rng.uniform(*x_range), rng.uniform(*y_range)])
            if len(others) == 0 or np.min(np.linalg.norm(others - candidate,
                                                         axis=1)) >= min_separation:
                break
        else:
            raise ValueError(f"cannot place {count} {what} {min_separation} m {apart} in "
                             f"x {list(x_range)}, y {list(y_range)}")
        points[index] = candidate
    return points


def jittered_grid(count, x_range, y_range, rng):
    """`(floor points (K, 2), cell size (dx, dy))`: K cells of a grid over the rectangle
    (about square cells), drawn without repeats, each point jittered within a quarter cell
    of its cell's centre, so two points are at least half a cell apart."""
    (x0, x1), (y0, y1) = x_range, y_range
    rows = max(1, int(np.ceil(np.sqrt(count * (x1 - x0) / (y1 - y0)))))
    columns = int(np.ceil(count / rows))
    dx, dy = (x1 - x0) / rows, (y1 - y0) / columns
    cells = rng.permutation(rows * columns)[:count]
    jitter = rng.uniform(-0.25, 0.25, (count, 2))
    points = np.stack([x0 + (cells // columns + 0.5 + jitter[:, 0]) * dx,
                       y0 + (cells % columns + 0.5 + jitter[:, 1]) * dy], axis=1)
    return points, (dx, dy)


def sample_grid_scene(seed, count, x_range=(1.25, 2.5), y_range=(-1.05, 1.05), height=0.7,
                      switch_schedule=(0.0, 0.3, 0.6), z_range=None):
    """`(scene, separation)`: a scene of many objects drawn from `seed`, one in each of
    `count` cells of a grid over the rectangle (`jittered_grid`), so that thousands are
    placed at once, at least `separation` (half a cell) apart; the targets are drawn as in
    `sample_reach_scene`, and with a `z_range` each object's height."""
    check_object_count((count, count), switch_schedule)
    rng = np.random.default_rng(seed)
    floor, cell = jittered_grid(count, x_range, y_range, rng)
    return _scene_on(rng, floor, height, switch_schedule, z_range), 0.5 * min(cell)


def validate_objects(objects, min_separation, reach_x=(0.3, 3.5), reach_height=(0.0, 1.1)):
    """Clear errors for objects the HSR cannot reach or that overlap (the first such object
    named). O(K log K) time and O(K) memory, so that a scene of thousands of goals is
    checked at once."""
    objects = np.asarray(objects, dtype=float)
    if objects.ndim != 2 or objects.shape[1] != 3 or len(objects) == 0:
        raise ValueError(f"objects must be (M, 3) with M >= 1, got shape {objects.shape}")
    if not np.isfinite(objects).all():
        raise ValueError("objects contain NaN or infinite values")
    heights = objects[:, 2]
    floor = np.linalg.norm(objects[:, :2], axis=1)
    out_of_reach = ((heights < reach_height[0]) | (heights > reach_height[1])
                    | (floor < reach_x[0]) | (floor > reach_x[1]))
    if out_of_reach.any():
        index = int(np.flatnonzero(out_of_reach)[0])
        point = objects[index]
        if not (reach_height[0] <= point[2] <= reach_height[1]):
            raise ValueError(f"object {index} at height {point[2]:.2f} m is out of the "
                             f"HSR's reach (heights {reach_height[0]}..{reach_height[1]} m)")
        raise ValueError(f"object {index} at {point.tolist()} is out of reach: keep "
                         f"objects {reach_x[0]}..{reach_x[1]} m from the robot")
    pair = closest_pair_within(objects, min_separation)
    if pair is not None:
        first, second, gap = pair
        raise ValueError(f"objects {first} and {second} overlap: {gap:.3f} m apart, "
                         f"less than {min_separation} m")
    return objects


def closest_pair_within(points, distance):
    """`(i, j, gap)` of the two closest of `points` `(K, D)` (i < j) if they are less than
    `distance` apart, else None. Sorted along x, only pairs less than `distance` apart in x
    are measured: one pass over K per neighbour in that band, not K^2 gaps."""
    points = np.asarray(points, dtype=float)
    order = np.argsort(points[:, 0], kind="stable")
    ordered = points[order]
    best = None
    for offset in range(1, len(points)):
        if not (ordered[offset:, 0] - ordered[:-offset, 0] < distance).any():
            break  # sorted along x: farther neighbours are farther apart in x too
        gaps = np.linalg.norm(ordered[offset:] - ordered[:-offset], axis=1)
        index = int(np.argmin(gaps))
        if gaps[index] < distance and (best is None or gaps[index] < best[2]):
            first, second = sorted((int(order[index]), int(order[index + offset])))
            best = (first, second, float(gaps[index]))
    return best


def reach_progress(position, start, target):
    """`1 - |p - target| / |start - target|`, clipped to [0, 1]."""
    total = vector_length(np.asarray(target) - start)
    if total <= 0.0:
        return 1.0
    return float(np.clip(1.0 - vector_length(np.asarray(target) - position) / total, 0.0, 1.0))


def wrap_angle(angle):
    """Angles (rad) brought into (-pi, pi]."""
    return np.angle(np.exp(1j * np.asarray(angle)))


def heading_error(heading, position, point):
    """Signed angle (rad, in (-pi, pi]) from `heading` to the floor direction to `point`."""
    direction = np.arctan2(point[1] - position[1], point[0] - position[0])
    return float(wrap_angle(direction - heading))


def rotate_planar(vector, angle):
    """The floor vector `(x, y)` turned by `angle` (rad): with the robot's heading, a
    robot-frame `(forward, left)` in the world frame."""
    cos, sin = np.cos(angle), np.sin(angle)
    return np.array([cos * vector[0] - sin * vector[1], sin * vector[0] + cos * vector[1]])
