"""DMP settings, the Gaussian basis, and the constants of one step.

The step constants (the 2x2 `Phi` and `Gamma` of the first-order-hold step and the phase
decay) depend on the settings, the duration and the step only, so they are pure functions
here, not state of a DMP; `step_matrices` is memoised and returns read-only arrays, which
every caller shares.
"""

import dataclasses
import functools
import math
import numbers

import numpy as np

from pbp_drake.core.choices import unknown_choice
from pbp_drake.core.linear import second_order_step

FORMULATIONS = ("ijspeert", "pastor")
# The most basis functions a DMP may have: far more than any trajectory needs (the paper
# uses 50), and a bound that refuses at once what would otherwise fail to allocate later.
MAX_BASIS_COUNT = 10_000


@dataclasses.dataclass
class DmpSettings:
    """Gains and basis of a DMP (scenario files: the `dmp` section).

    A plain dataclass, so that `yaml_load_typed` can read it; a `DmpBankModel` keeps its own copy.
    """

    #: ijspeert or pastor.
    formulation: str = "ijspeert"
    #: The number of Gaussian basis functions, 2 to MAX_BASIS_COUNT (10,000).
    basis_count: int = 50
    #: The damping gain (1/s).
    alpha_z: float = 25.0
    #: The stiffness ratio; None for alpha_z / 4 (critically damped).
    beta_z: float | None = None
    #: The phase decay; ln 100 makes the phase reach 0.01 at t = tau.
    alpha_x: float = math.log(100.0)
    #: A taught primitive's file (`pbp-drake teach`; scenario files: relative to the
    #: file's folder): every goal's DMP takes its shape (`pbp_drake.core.dmp.primitive`),
    #: and the fields above must be the ones it was fitted with. Empty: straight paths,
    #: or a 2-D scene's demonstration.
    primitive: str = ""

    def __post_init__(self):
        self.validate()

    def validate(self):
        """Raises ValueError naming the first field that cannot be used (a YAML loader sets
        the fields after construction, so `resolve` calls this again)."""
        if self.formulation not in FORMULATIONS:
            raise ValueError(unknown_choice("formulation", self.formulation, FORMULATIONS))
        count = self.basis_count
        if isinstance(count, bool) or not (isinstance(count, numbers.Real)
                                           and math.isfinite(count) and int(count) == count):
            raise ValueError(f"basis_count must be a whole number, got {count!r}")
        self.basis_count = int(count)  # 10.0 sizes arrays as 10 does
        if self.basis_count < 2:
            raise ValueError(f"basis_count must be at least 2, got {self.basis_count}")
        if self.basis_count > MAX_BASIS_COUNT:
            raise ValueError(f"basis_count must be at most {MAX_BASIS_COUNT}, got "
                             f"{self.basis_count}")
        for name in ("alpha_z", "alpha_x", "beta_z"):
            value = getattr(self, name)
            if name == "beta_z" and value is None:
                continue
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise ValueError(f"{name} must be a number, got {value!r}")
            if not value > 0:
                raise ValueError(f"{name} must be positive, got {value}")
            if not math.isfinite(value):
                raise ValueError(f"{name} must be finite, got {value}")

    @property
    def stiffness(self):
        """`K = alpha_z beta_z`."""
        beta_z = self.alpha_z / 4.0 if self.beta_z is None else self.beta_z
        return self.alpha_z * beta_z

    @property
    def damping(self):
        """`D = alpha_z`."""
        return self.alpha_z

    def basis(self):
        """Centres `c_i = exp(-alpha_x i / (N - 1))` and widths crossing neighbours at 0.7."""
        n = self.basis_count
        centres = np.exp(-self.alpha_x * np.arange(n) / (n - 1))
        widths = np.empty(n)
        widths[:-1] = 4.0 * math.log(1.0 / 0.7) / np.diff(centres) ** 2
        widths[-1] = widths[-2]
        return centres, widths


def normalized_basis(phase, centres, widths):
    """`psi_i(x) / sum_j psi_j(x)` for phases of any shape: returns `(N,) + phase.shape`."""
    phase = np.asarray(phase, dtype=float)
    offsets = phase[np.newaxis, ...] - centres.reshape((-1,) + (1,) * phase.ndim)
    psi = np.exp(-widths.reshape((-1,) + (1,) * phase.ndim) * offsets**2)
    return psi / psi.sum(axis=0)


@functools.lru_cache(maxsize=256)
def step_matrices(stiffness, damping, duration, dt):
    """The read-only 2x2 `(Phi, Gamma)` of one step of the transformation system around its
    moving attractor (`linear.second_order_step`), one pair for every goal and dimension.

    Keyed on plain floats, not on `DmpSettings`, because hashing four floats is cheap enough
    for a call every control step and hashing the dataclass is not."""
    phi, gamma = second_order_step(stiffness, damping, duration, dt)
    phi, gamma = np.array(phi), np.array(gamma)
    phi.setflags(write=False)
    gamma.setflags(write=False)
    return phi, gamma


def phase_decay(settings, duration, dt):
    """The phase factor `exp(-alpha_x dt / tau)` of one step."""
    return math.exp(-settings.alpha_x * dt / duration)
