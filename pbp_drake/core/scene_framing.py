"""Where a 2-D scene is and how to frame it on a page, a perspective camera framed on a 3-D
workspace (`workspace_view`), and paths resampled to a fixed count of points (for drawing them
with a fixed set of Meshcat objects).

Meshcat's page keeps an orthographic camera's `left`, `top` and `bottom` and fits `right` to
the page's aspect (`right = left + width * (top - bottom) / height`). So a view cannot be
centred on every page: `page_view` centres the scene on a 16:9 page and makes it fit, margin
included, on any page at least 4:3 wide (on a wider page the spare room is on the right).
"""

import numpy as np

CENTRED_ASPECT = 16.0 / 9.0  # the page width / height on which the scene sits centred
NARROWEST_ASPECT = 4.0 / 3.0  # the narrowest page on which all of the scene still shows


def scene_bounds(points, circles=(), margin_fraction=0.1, min_margin=0.1):
    """The box `(low, high)` (2-vectors) that holds every point of `points` `(N, 2)` and
    every circle of `circles` (`(centre, radius)` pairs), with a margin on every side of
    `margin_fraction` of the larger side, and at least `min_margin` (markers have a size)."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    corners = [points]
    for centre, radius in circles:
        centre = np.asarray(centre, dtype=float)[:2]
        corners.append(np.array([centre - radius, centre + radius]))
    points = np.concatenate(corners)
    low, high = points.min(axis=0), points.max(axis=0)
    margin = max(min_margin, margin_fraction * float(np.max(high - low)))
    return low - margin, high + margin


def page_view(low, high, centred_aspect=CENTRED_ASPECT, narrowest_aspect=NARROWEST_ASPECT):
    """The view `(xmin, xmax, ymin, ymax)` to give Meshcat's orthographic camera for the box
    `(low, high)`: centred on a page of `centred_aspect`, and the whole box inside the page
    on every page at least `narrowest_aspect` wide (Meshcat keeps xmin, ymin and ymax).

    With a view height h the page shows `[xmin, xmin + aspect * h]`; the box of width w
    starts at `xmin + (centred_aspect * h - w) / 2` and must end by `xmin + narrowest_aspect
    * h`, hence h >= w / (2 * narrowest_aspect - centred_aspect).
    """
    low, high = np.asarray(low, float), np.asarray(high, float)
    width, height = high - low
    height = max(height, width / (2.0 * narrowest_aspect - centred_aspect))
    centre = (low + high) / 2.0
    half_width = centred_aspect * height / 2.0
    return (centre[0] - half_width, centre[0] + half_width,
            centre[1] - height / 2.0, centre[1] + height / 2.0)


# Meshcat's perspective camera: 75 degrees of vertical field of view (three.js, as Meshcat
# sets it up), on a page at least as wide as it is tall.
MESHCAT_FIELD_OF_VIEW = np.radians(75.0)
# From the workspace's centre toward the camera: behind the robot (-x), to its right (-y)
# and above, the direction of the HSR's default view.
VIEW_DIRECTION = (-0.57, -0.43, 0.70)
WORKSPACE_FILL = 0.6  # the share of the view's height the workspace spans


def workspace_view(points, fill=WORKSPACE_FILL, direction=VIEW_DIRECTION,
                   field_of_view=MESHCAT_FIELD_OF_VIEW, min_radius=0.1):
    """`(camera, target)` (world frame) of a perspective camera looking at the centre of the
    box around `points` `(N, 3)` from `direction`, at the distance at which the ball around
    them (radius at least `min_radius`) spans `fill` of the vertical `field_of_view`."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    centre = (points.min(axis=0) + points.max(axis=0)) / 2.0
    radius = max(min_radius, float(np.max(np.linalg.norm(points - centre, axis=1))))
    # Seen from d away, the ball's half angle is asin(radius / d).
    distance = radius / np.sin(fill * field_of_view / 2.0)
    direction = np.asarray(direction, dtype=float)
    return centre + distance * direction / np.linalg.norm(direction), centre


def resample_by_arc_length(path, count):
    """`count` points `(count, D)` evenly spaced along the polyline `path` `(N, D)`, from its
    first point to its last (all at the first point when the path has no length)."""
    path = np.atleast_2d(np.asarray(path, dtype=float))
    steps = np.linalg.norm(np.diff(path, axis=0), axis=1)
    along = np.concatenate([[0.0], np.cumsum(steps)])
    if along[-1] <= 0.0:
        return np.repeat(path[:1], count, axis=0)
    wanted = np.linspace(0.0, along[-1], count)
    return np.column_stack([np.interp(wanted, along, column) for column in path.T])
