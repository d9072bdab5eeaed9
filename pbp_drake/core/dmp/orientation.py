"""Orientation DMPs on unit quaternions `(w, x, y, z)`: the formulation, the one-demonstration
fit, and one DMP stepped the plain way (the readable reference the vectorised bank is
tested against).

The formulation is Koutras and Doulgeri's (2020): the position DMP, unchanged, on
`e = Log(q g*)` (3,), with goal 0 and start `e0 = Log(q0 g*)`; then `q = Exp(e) g` and
`omega = J(e) de/dt` (`quaternion.left_jacobian_times`). The velocity state kept is
`eta = tau omega` (world frame), not `z`, so that PBP's goal switch and phase lock can copy
it as the position DMP does `z`. The step, and why a demonstration must stay within 180
degrees of its last orientation: docs/concepts/dmp.md, "Orientation DMPs"."""

import numpy as np

from pbp_drake.core import quaternion
from pbp_drake.core.dmp._checks import as_point, positive
from pbp_drake.core.dmp.fitting import check_times, fit_weights
from pbp_drake.core.dmp.settings import DmpSettings
from pbp_drake.core.dmp.single import SingleDmp

AXES = 3


def orientation_errors(orientations, goals):
    """`e = Log(q g*)`, `(3, ...)`, of orientations and goals `(4, ...)` (broadcast)."""
    return quaternion.log_map(quaternion.multiply(orientations, quaternion.conjugate(goals)))


def validate_orientation_demonstration(times, orientations):
    """Checks a demonstration and returns float arrays `(T,)`, unit quaternion rows `(T, 4)`.

    Refuses (ValueError) fewer than 3 samples, times that are not finite and increasing,
    non-unit or NaN quaternions, and a path that turns through 180 degrees away from its
    last orientation (the log of the error would jump there)."""
    orientations = quaternion.unit_quaternions(orientations, "demonstration orientations")
    if orientations.ndim != 2 or orientations.shape[0] < 3:
        raise ValueError(f"demonstration orientations must be (T, 4) with T >= 3, got shape "
                         f"{orientations.shape}")
    times = check_times(times, orientations.shape[0])
    errors = orientation_errors(orientations.T, orientations[-1][:, np.newaxis])
    jumps = np.flatnonzero(np.linalg.norm(np.diff(errors, axis=1), axis=0) > np.pi)
    if jumps.size:
        raise ValueError(f"demonstration orientations pass 180 degrees from the last one "
                         f"between samples {jumps[0]} and {jumps[0] + 1}; orientation DMPs "
                         f"need a demonstration that stays within 180 degrees of its end")
    return times, orientations


def fit_orientation_weights(times, orientations, settings=DmpSettings()):
    """Weights `(N, 3)` and amplitude scaling `(3,)` of ONE demonstration of orientations
    `(T, 4)`: the position fit (`fitting.fit_weights`) on `e_t = Log(q_t q_T*)`."""
    times, orientations = validate_orientation_demonstration(times, orientations)
    errors = orientation_errors(orientations.T, orientations[-1][:, np.newaxis]).T
    return fit_weights(times, errors, settings)


class OrientationDmp(SingleDmp):
    """One orientation DMP, stepped with a plain per-axis loop: the readable reference.

    State: `phase`, `orientation` (4,) and `scaled_angular_velocity` (3,) `eta = tau omega`.
    `straight` (`SingleDmp`'s) turns along the shorter arc from `start` to `goal` (a slerp
    path); `rollout` is `SingleDmp`'s too.
    """

    PATH = "orientation"

    def __init__(self, weights, start, goal, duration, settings=DmpSettings(),
                 amplitude_scaling=None):
        super().__init__(weights, start, goal, duration, settings, amplitude_scaling, AXES)

    @staticmethod
    def _ends(start, goal):
        return (quaternion.unit_quaternions(start, "start").reshape(4),
                quaternion.unit_quaternions(goal, "goal").reshape(4))

    @staticmethod
    def _span(start, goal):
        return -orientation_errors(start, goal)

    @classmethod
    def from_demonstration(cls, times, orientations, settings=DmpSettings()):
        """Learns the DMP of ONE demonstration `(T, 4)`; start, goal, duration are its own."""
        times, orientations = validate_orientation_demonstration(times, orientations)
        weights, scaling = fit_orientation_weights(times, orientations, settings)
        return cls(weights, orientations[0], orientations[-1], times[-1] - times[0],
                   settings, scaling)

    def reset(self, orientation=None, scaled_angular_velocity=None):
        """Phase 1, orientation `start` (or given), scaled angular velocity 0 (or given)."""
        self.phase = 1.0
        self.orientation = (self.start.copy() if orientation is None else
                            quaternion.unit_quaternions(orientation, "orientation").reshape(4))
        self.scaled_angular_velocity = (
            np.zeros(AXES) if scaled_angular_velocity is None
            else as_point(scaled_angular_velocity, "scaled_angular_velocity", dimension=AXES))

    def attractor(self, phase, goal):
        """The moving attractor `a(x)` in `e = Log(q g*)` coordinates, `(3,)`."""
        start_error = orientation_errors(self.start, goal)
        shape = self._shape(phase)
        result = np.empty(AXES)
        for axis in range(AXES):
            if self._settings.formulation == "ijspeert":
                amplitude = -start_error[axis] if self.amplitude_scaling[axis] else 1.0
                result[axis] = shape[axis] * amplitude / self._settings.stiffness
            else:
                result[axis] = start_error[axis] * phase + shape[axis]
        return result

    def next_step(self, dt, goal=None, robot_orientation=None, robot_angular_velocity=None,
                  phase_locked=False):
        """One control step from the robot's orientation; returns (orientation (4,),
        angular velocity (3,)).

        `robot_orientation` replaces the DMP's (PBP's re-integration); while
        `phase_locked`, the phase stays, the orientation is the robot's and the angular
        velocity follows `robot_angular_velocity`."""
        positive(dt, "dt")
        goal = (self.goal if goal is None
                else quaternion.unit_quaternions(goal, "goal").reshape(4))
        if robot_orientation is not None:
            self.orientation = quaternion.unit_quaternions(
                robot_orientation, "robot_orientation").reshape(4)
        tau = self.duration
        if phase_locked:
            if robot_angular_velocity is not None:
                self.scaled_angular_velocity = tau * np.asarray(robot_angular_velocity, float)
            return self.orientation.copy(), self.scaled_angular_velocity / tau
        error = orientation_errors(self.orientation, goal)
        z = quaternion.left_jacobian_inverse_times(error, self.scaled_angular_velocity)
        new_error, new_z = self._free_step(error, z, dt, goal)
        self.orientation = quaternion.aligned(
            quaternion.multiply(quaternion.exp_map(new_error), goal), self.orientation)
        self.scaled_angular_velocity = quaternion.left_jacobian_times(new_error, new_z)
        return self.orientation.copy(), self.scaled_angular_velocity / tau
