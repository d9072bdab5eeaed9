"""A point robot in D dimensions: a unit-free mass-spring-damper tracking a reference.

`m a = k (r - p) + c (v_r - v)`, with the commanded position `r` and velocity `v_r` held over
each plant step. The step is the exact zero-order-hold solution, so the Drake system and any
plain NumPy loop that use it agree to rounding.
"""

import numpy as np

from pbp_drake.core.linear import expm


class MassSpringDamper:
    """Exact discrete-time mass-spring-damper, the same for every axis."""

    def __init__(self, mass=1.0, stiffness=400.0, damping=40.0, time_step=0.001):
        for name, value in (("mass", mass), ("stiffness", stiffness),
                            ("time_step", time_step)):
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"robot.{name} must be positive, got {value}")
        if not (np.isfinite(damping) and damping >= 0):
            raise ValueError(f"robot.damping must be non-negative, got {damping}")
        self.time_step = float(time_step)
        # State [p, v, r, v_r]; the reference parts are constant over the step.
        rates = np.zeros((4, 4))
        rates[0, 1] = 1.0
        rates[1] = [-stiffness / mass, -damping / mass, stiffness / mass, damping / mass]
        self._transition = expm(rates * time_step)[:2]  # (2, 4): rows for p and v

    def step(self, position, velocity, reference_position, reference_velocity):
        """One plant step; each argument is (D,); returns the new (position, velocity)."""
        stacked = np.stack([position, velocity, reference_position, reference_velocity])
        new = self._transition @ stacked
        return new[0], new[1]
