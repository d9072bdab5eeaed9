"""Writes around_the_wall.csv beside this file: a scripted demonstration for
diagrams/hsr_wall.yaml, the HSR's hand from its start around the left end of the wall
(x = 1.1 m, up to y = 0.45 m with the cylinders' radius) to a target behind it, at the
task's height, in the columns `pbp-drake run --log` writes. Then

    pbp-drake teach diagrams/hsr_wall.yaml --from diagrams/primitives/around_the_wall.csv \\
        --output diagrams/primitives/around_the_wall.json

teaches the shipped primitive from it (docs/tasks/teach.md)."""

import pathlib

import numpy as np

START = (0.531, 0.078)  # the HSR hand's start in the task (m)
GOAL = (2.4, 0.02)  # a target behind the wall
WALL_X, DETOUR, WIDTH = 1.1, 0.6, 0.15  # m: where the path passes the wall, how far aside
HEIGHT, SPEED, PERIOD = 0.7, 0.12, 0.03  # m, m/s, s: the task's height, speed and tick


def demonstration():
    """Times (T,) and positions (T, 3): minimum-jerk progress along x, the straight line in
    y plus a bump of DETOUR centred where x is at the wall (zero at both ends)."""
    start, goal = np.array(START), np.array(GOAL)
    at_wall = (WALL_X - start[0]) / (goal[0] - start[0])

    def bump(s):
        return DETOUR * np.exp(-((s - at_wall) / WIDTH) ** 2)

    duration = 1.5 * np.linalg.norm(goal - start) / SPEED
    times = np.arange(0.0, duration + PERIOD / 2, PERIOD)
    s = times / times[-1]
    progress = 10 * s**3 - 15 * s**4 + 6 * s**5
    xy = start + np.outer(progress, goal - start)
    xy[:, 1] += bump(progress) - (bump(0.0) * (1 - progress) + bump(1.0) * progress)
    return times, np.column_stack([xy, np.full(len(times), HEIGHT)])


def main():
    times, positions = demonstration()
    rows = ["time,ee_x,ee_y,ee_z"] + [f"{t!r},{x!r},{y!r},{z!r}"
                                      for t, (x, y, z) in zip(times.tolist(),
                                                              positions.tolist())]
    path = pathlib.Path(__file__).with_suffix(".csv")
    path.write_text("\n".join(rows) + "\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
