"""Discrete Dynamical Movement Primitives (DMPs) in D dimensions, and banks of K of them,
NumPy only: `DmpSettings`, `Dmp` (one DMP, the readable reference), `DmpBankModel` (K DMPs
as one immutable model, with the caller's `DmpWorkspace`), and their orientation twins on
unit quaternions `(w, x, y, z)` (`OrientationDmp`, `OrientationDmpBank`). The formulas
(the ``"ijspeert"`` and ``"pastor"`` formulations, the closed-form first-order-hold step,
PBP's re-integration from the robot's measured position, the bank and the orientation
DMPs) are in docs/concepts/dmp.md. Notation as in Ijspeert et al. 2013: `y` position,
`z = tau dy/dt` scaled velocity, `x` phase, `g` goal, `y0` start, `tau` duration."""

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
