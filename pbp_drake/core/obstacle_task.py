"""The dynamic-obstacle task of the paper (section IV-B.2), in pure NumPy.

One target object; cylinder obstacles stand still at random places until the robot's
progress to the target passes each one's activation threshold. An activated obstacle then
moves, at a fixed speed, to intercept the robot at the midpoint of the line from the
robot (as it stood at activation) to the target, and stops there.
"""

import dataclasses

import numpy as np

from pbp_drake.core.reach_task import spread_points


@dataclasses.dataclass(frozen=True)
class ObstacleScene:
    """The target `(3,)`, obstacles' start positions `(N, 2)` on the floor and their
    activation thresholds `(N,)` (fractions of progress)."""

    target: np.ndarray
    obstacle_starts: np.ndarray
    thresholds: np.ndarray


def sample_obstacle_scene(seed, x_range=(1.25, 2.5), y_range=(-1.05, 1.05), height=0.7,
                          obstacle_count=3, obstacle_x_range=(0.9, 2.6),
                          obstacle_y_range=(-1.3, 1.3), activation_range=(0.05, 0.5),
                          clearance=0.45, robot_xy=(0.0, 0.0), fixed_starts=None):
    """Draws a scene from `seed` alone. Obstacles start at least `clearance` from the
    robot's base, the target and each other, so that nothing starts in collision. With
    `fixed_starts` `(N, 2)` the obstacles start there (a wall may stand closer together),
    and the target is drawn again until it is `clearance` from each."""
    rng = np.random.default_rng(seed)
    target = np.array([rng.uniform(*x_range), rng.uniform(*y_range), height])
    if fixed_starts is not None:
        starts = np.asarray(fixed_starts, float).reshape(-1, 2)
        for _ in range(1000):
            if np.all(np.linalg.norm(starts - target[:2], axis=1) >= clearance):
                break
            target = np.array([rng.uniform(*x_range), rng.uniform(*y_range), height])
        else:
            raise ValueError(f"cannot draw a target {clearance} m from every obstacle in x "
                             f"{list(x_range)}, y {list(y_range)}")
    else:
        starts = spread_points(
            rng, obstacle_count, obstacle_x_range, obstacle_y_range, clearance, "obstacles",
            keep_away=[np.asarray(robot_xy, float), target[:2]],
            apart="from the robot, the target and each other")
    thresholds = np.sort(rng.uniform(*activation_range, size=len(starts)))
    return ObstacleScene(target=target, obstacle_starts=starts, thresholds=thresholds)


def step_obstacles(positions, intercepts, active, progress, robot_xy, target_xy, thresholds,
                   speed, dt):
    """One control step of the obstacles `positions` (N, 2), each `active` (N,) one moving
    to its intercept (N, 2), woken when the robot's `progress` (0 to 1) reaches its
    threshold; `robot_xy`, `target_xy` (2,) on the floor. Pure: returns new
    `(positions, intercepts, active)`."""
    positions = np.array(positions, dtype=float)
    intercepts = np.array(intercepts, dtype=float)
    active = np.array(active, dtype=bool)
    waking = ~active & (progress >= np.asarray(thresholds))
    if np.any(waking):
        intercepts[waking] = (np.asarray(robot_xy) + np.asarray(target_xy)) / 2.0
        active = active | waking
    offset = intercepts - positions
    distance = np.linalg.norm(offset, axis=1)
    travel = np.minimum(distance, speed * dt)
    moving = active & (distance > 0.0)
    positions[moving] += offset[moving] * (travel[moving] / distance[moving])[:, None]
    return positions, intercepts, active
