"""Discrete Dynamical Movement Primitives (DMPs) in D dimensions, and banks of K of them.

The formulas (the ``"ijspeert"`` and ``"pastor"`` formulations, both written around a moving
attractor, the closed-form first-order-hold step, how PBP re-integrates from the robot's
measured position while the DMP keeps its own velocity, the bank and the orientation DMPs)
are in docs/concepts/dmp.md. Notation as in Ijspeert et al. 2013: `y` position,
`z = tau dy/dt` scaled velocity, `x` phase, `g` goal, `y0` start, `tau` duration.

The modules, all NumPy only (no Drake import):

- `settings`: `DmpSettings`, the basis, and the memoised constants of one step;
- `stepping`: the bank's step, vectorised over goals and dimensions (mixed into `DmpBankModel`);
- `fitting`: `minimum_jerk`, `validate_demonstration`, `fit_weights` (one demonstration);
- `single`: `Dmp`, one DMP with a stateful API, the readable reference;
- `bank`: `DmpBankModel`, K DMPs as one immutable model, stepped by pure and in-place calls;
- `workspace`: `DmpWorkspace`, the scratch arrays a caller of the in-place step owns;
- `orientation`: orientation DMPs on unit quaternions `(w, x, y, z)`, the position DMP on
  `e = Log(q g*)` (Koutras and Doulgeri 2020), its fit, and `OrientationDmp`, the reference;
- `orientation_bank`: `OrientationDmpBank`, K of them with the position bank's API;
- `orientation_kernels`: its step's quaternion math into an `OrientationWorkspace`.
"""

from pbp_drake.core.dmp.bank import DmpBankModel
from pbp_drake.core.dmp.fitting import fit_weights, minimum_jerk, validate_demonstration
from pbp_drake.core.dmp.orientation import OrientationDmp, fit_orientation_weights
from pbp_drake.core.dmp.orientation_bank import OrientationDmpBank
from pbp_drake.core.dmp.orientation_kernels import OrientationWorkspace
from pbp_drake.core.dmp.settings import (
    FORMULATIONS, DmpSettings, normalized_basis, phase_decay, step_matrices)
from pbp_drake.core.dmp.single import Dmp
from pbp_drake.core.dmp.workspace import DmpWorkspace

__all__ = [
    "FORMULATIONS", "Dmp", "DmpBankModel", "DmpSettings", "DmpWorkspace", "OrientationDmp",
    "OrientationDmpBank", "OrientationWorkspace", "fit_orientation_weights", "fit_weights",
    "minimum_jerk", "normalized_basis", "phase_decay", "step_matrices",
    "validate_demonstration",
]
