"""Discrete Dynamical Movement Primitives (DMPs) in D dimensions, and a bank of K of them.

Notation (as in Ijspeert et al. 2013): `y` position, `z = tau * dy/dt` scaled velocity,
`x` phase, `g` goal, `y0` start, `tau` duration. Two formulations, chosen by name:

- ``"ijspeert"`` (the paper's form):
  `tau dz = alpha_z (beta_z (g - y) - z) + f(x)`, `f(x) = (psi.w / sum psi) x (g - y0)`;
- ``"pastor"`` (Pastor et al. 2009, Hoffmann et al. 2009; robust to goal changes and to
  `g` close to `y0`): `tau dz = K (g - y) - D z - K (g - y0) x + K (psi.w / sum psi) x`.

With `K = alpha_z beta_z` and `D = alpha_z`, both read `tau dz = K (y_attr - y) - D z`
around a moving attractor

- ijspeert: `y_attr = g + (psi.w / sum psi) x a / K`, `a = g - y0` (or 1 where the
  demonstration's amplitude guard switched the scaling off);
- pastor:   `y_attr = g - (g - y0) x + (psi.w / sum psi) x`,

so one closed-form step serves both, at the cost of two 2x2 matrices shared by every goal
and dimension. Over a step the attractor is taken linear in time between its values at the
step's phase and at the next phase (a first-order hold): with `A` the system's matrix,
`Phi = expm(A dt)` and `Gamma = integral_0^dt expm(A s) ds` (`settings.step_matrices`),
`e = y - y_attr(x0)` and `r = (y_attr(x1) - y_attr(x0)) / dt`,

    y' = y_attr(x1) + Phi00 e + Phi01 z - Gamma00 r,    z' = Phi10 e + Phi11 z - Gamma10 r.

The step is exact for an attractor linear in time over the step, and second order in dt
for the real one (the phase decays exponentially and the basis is Gaussian): on a 1 m
minimum-jerk reach with tau = 1.5 s it is 0.31 mm from the continuous ODE at 30 Hz and
0.044 mm at 100 Hz, where holding the attractor constant over the step (zero-order hold,
first order) was 20.8 mm and 6.2 mm off (`tests/core/test_dmp.py`).

PBP re-integrates the DMP every control step from the robot's measured position. The DMP
keeps its own velocity state: resetting it to the robot's measured velocity each step stalls
the DMP behind a lagging tracker (the re-integration trap). Only while the phase is locked (the
operator is driving, PBP-Alt) does the DMP's velocity follow the robot's, so that it resumes
from the robot's actual state when the operator lets go.

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
    FORMULATIONS, DmpSettings, normalized_basis, phase_decay, step_matrices, transition)
from pbp_drake.core.dmp.single import Dmp
from pbp_drake.core.dmp.workspace import DmpWorkspace

__all__ = [
    "FORMULATIONS", "Dmp", "DmpBankModel", "DmpSettings", "DmpWorkspace", "OrientationDmp",
    "OrientationDmpBank", "OrientationWorkspace", "fit_orientation_weights", "fit_weights",
    "minimum_jerk", "normalized_basis", "phase_decay", "step_matrices", "transition",
    "validate_demonstration",
]
