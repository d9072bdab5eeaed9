"""Geometry of the paper's 2-D toy scenes and its virtual human (section IV-A, Eq. 5).

Obstacles are discs (spheres in 3-D): a centre and a radius. The robot is a point.
"""

import numpy as np

from pbp_drake.core.coordinates import is_real


def obstacle_distances(positions, centres, radii):
    """Signed distances `(..., M)` from points `(..., D)` to the surfaces of M obstacles."""
    positions = np.asarray(positions, dtype=float)
    centres = np.asarray(centres, dtype=float).reshape(-1, positions.shape[-1])
    offsets = positions[..., np.newaxis, :] - centres
    return np.linalg.norm(offsets, axis=-1) - np.asarray(radii, dtype=float)


def collision_ratio(positions, centres, radii):
    """The ratio of states `(T, D)` inside any obstacle (the paper's collision metric)."""
    if len(radii) == 0:
        return 0.0
    # One radius an obstacle: NumPy would broadcast other counts into another scene.
    centre_count = np.asarray(centres, dtype=float).size // np.shape(positions)[-1]
    if len(radii) != centre_count:
        raise ValueError(f"radii has {len(radii)} values for {centre_count} centres; "
                         "expected one radius an obstacle")
    inside = (obstacle_distances(positions, centres, radii) < 0.0).any(axis=-1)
    return float(inside.mean())


def repulsion_command(position, centres, radii, distance_threshold=0.2, speed=1.0, axis=None):
    """The paper's virtual human: a command of magnitude `speed` away from the nearest obstacle
    when it is closer than `distance_threshold`, else zero. Returns (command, active).

    With `axis`, the command is `sign(.) * speed * axis` (Eq. 5's sign along one axis, the
    sign pushing away from the obstacle; on the axis itself it pushes along +axis). Without,
    it points radially away from the obstacle's centre.
    """
    position = np.asarray(position, dtype=float)
    if len(radii) == 0:
        return np.zeros_like(position), False
    distances = obstacle_distances(position, centres, radii)
    nearest = int(np.argmin(distances))
    if distances[nearest] >= distance_threshold:
        return np.zeros_like(position), False
    away = position - np.asarray(centres, dtype=float).reshape(-1, position.size)[nearest]
    if axis is not None:
        axis = np.asarray(axis, dtype=float)
        direction = (1.0 if away @ axis >= 0.0 else -1.0) * axis / np.linalg.norm(axis)
    else:
        norm = np.linalg.norm(away)
        direction = away / norm if norm > 0 else np.eye(position.size)[-1]
    return speed * direction, True


def bent_path(start, goal, bend, duration, sample_count=200):
    """A demonstration that bows sideways by `bend` at mid-path (a detour around an obstacle),
    timed with a minimum-jerk profile. Returns times `(T,)` and positions `(T, 2)`."""
    start = np.asarray(start, dtype=float).reshape(-1)
    goal = np.asarray(goal, dtype=float).reshape(-1)
    for name, point in (("start", start), ("goal", goal)):
        if point.size != 2 or not np.isfinite(point).all():
            raise ValueError(f"{name} must be two finite numbers (x, y), got {point.tolist()}")
    if np.hypot(*(goal - start)) < 1e-6:
        raise ValueError(f"goal {goal.tolist()} is where start is; the bend's side is "
                         "undefined")
    if not (is_real(duration) and np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be positive and finite, got {duration!r}")
    times = np.linspace(0.0, duration, sample_count)
    s = times / duration
    progress = 10 * s**3 - 15 * s**4 + 6 * s**5
    along = goal - start
    normal = np.array([-along[1], along[0]]) / np.linalg.norm(along)
    positions = (start + np.outer(progress, along)
                 + np.outer(bend * np.sin(np.pi * progress), normal))
    return times, positions
