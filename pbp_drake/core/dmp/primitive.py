"""A primitive taught by driving: ONE demonstration's DMP shape, kept as a document and sent
to any goal (`pbp-drake teach` writes one; a scenario's `dmp: {primitive: FILE}` reads it).

`teach_primitive(times, positions, settings)` fits the demonstration (`fit_weights`, either
formulation) and measures the fit: the DMP rolled out from the demonstration's start to its
own goal, against the demonstration, as an RMS distance (`fit_error`, m). A bank of every
goal's DMP with the taught shape is `primitive_bank`; the shape is carried to each goal as
the formulation carries it (Ijspeert: scaled by each goal's `g - y0` where the
demonstration's amplitude allowed, else as learned; Pastor: as learned).

The document (`primitive_document`, `read_primitive_document`) is plain JSON data:

- `format` (`PRIMITIVE_FORMAT`) and `version` (`FORMAT_VERSION`; a newer one is refused);
- `settings`: the DMP's formulation, basis_count, alpha_z, beta_z and alpha_x;
- `dimension`, `weights` (basis_count rows of `dimension` numbers), `amplitude_scaling`;
- `demonstration`: its `times` (s) and `positions` (m), from which `start`, `goal`,
  `duration` and `length_ratio` (path length over start-to-goal distance) follow;
- `fit_error` (m).
"""

import dataclasses

import numpy as np

from pbp_drake.core.dmp.bank import DmpBankModel
from pbp_drake.core.dmp.fitting import fit_weights, validate_demonstration
from pbp_drake.core.dmp.settings import DmpSettings
from pbp_drake.core.dmp.single import Dmp

#: The document's `format`.
PRIMITIVE_FORMAT = "pbp_drake.primitive"
#: The newest document version this code reads and the one it writes.
FORMAT_VERSION = 1
#: Fewest samples a demonstration needs (the fit's derivatives need a few at each end).
MIN_SAMPLES = 10
#: Least distance (m) from a demonstration's start to its end: a shape is sent from a
#: start to a goal, and one that ends where it began has no direction to send.
MIN_TRAVEL = 0.02
#: The gains a primitive keeps (with its formulation and basis): `DmpSettings`' own.
SETTINGS_FIELDS = ("formulation", "basis_count", "alpha_z", "beta_z", "alpha_x")


@dataclasses.dataclass(frozen=True)
class Primitive:
    """A taught DMP shape: the fit's `settings`, `weights` (N, D), `amplitude_scaling`
    (D,), the demonstration (`times` (T,), `positions` (T, D)) and `fit_error` (m)."""

    settings: DmpSettings
    weights: np.ndarray
    amplitude_scaling: np.ndarray
    times: np.ndarray
    positions: np.ndarray
    fit_error: float

    @property
    def dimension(self):
        return self.positions.shape[1]

    @property
    def start(self):
        return self.positions[0]

    @property
    def goal(self):
        return self.positions[-1]

    @property
    def duration(self):
        return float(self.times[-1] - self.times[0])

    @property
    def length_ratio(self):
        """The demonstration's path length over its start-to-goal distance (>= 1): a bank
        given a straight path's duration takes this much longer along the shape."""
        length = np.linalg.norm(np.diff(self.positions, axis=0), axis=1).sum()
        return float(length / np.linalg.norm(self.goal - self.start))


def teach_primitive(times, positions, settings=DmpSettings()) -> Primitive:
    """The primitive of one demonstration `times` (T,), `positions` (T, D); ValueError when
    it is too short, does not move, or has NaN (the message says which)."""
    times, positions = validate_demonstration(times, positions)
    if len(times) < MIN_SAMPLES:
        raise ValueError(f"the demonstration has {len(times)} samples; at least "
                         f"{MIN_SAMPLES} are needed")
    travel = float(np.linalg.norm(positions[-1] - positions[0]))
    if travel < MIN_TRAVEL:
        raise ValueError(f"the demonstration ends {travel:.3f} m from where it starts; a "
                         f"primitive needs at least {MIN_TRAVEL} m")
    weights, scaling = fit_weights(times, positions, settings)
    fit = _fit_error(times, positions, weights, scaling, settings)
    return Primitive(dataclasses.replace(settings), weights, scaling, times - times[0],
                     positions, fit)


def _fit_error(times, positions, weights, scaling, settings):
    """RMS distance (m) between the demonstration and its DMP rolled out from its start to
    its goal, over its duration, compared at the demonstration's own times."""
    duration = times[-1] - times[0]
    dmp = Dmp(weights, positions[0], positions[-1], duration, settings, scaling)
    steps = max(len(times) - 1, int(np.ceil(duration / 0.01)))
    path = dmp.rollout(duration / steps)
    at = np.linspace(0.0, duration, steps + 1)
    reproduced = np.column_stack([np.interp(times - times[0], at, path[:, d])
                                  for d in range(positions.shape[1])])
    return float(np.sqrt(np.mean(np.sum((reproduced - positions) ** 2, axis=1))))


def primitive_bank(primitive: Primitive, start, goal_count, duration=None) -> DmpBankModel:
    """`goal_count` DMPs from `start` with the primitive's shape (goals given at run time),
    of `duration` (s; the demonstration's when None)."""
    return DmpBankModel(primitive.weights, start,
                        primitive.duration if duration is None else duration,
                        primitive.settings, primitive.amplitude_scaling, goal_count)


def primitive_document(primitive: Primitive) -> dict:
    """The primitive as plain JSON data (the module's docstring)."""
    return {"format": PRIMITIVE_FORMAT, "version": FORMAT_VERSION,
            "settings": {name: getattr(primitive.settings, name) for name in SETTINGS_FIELDS},
            "dimension": primitive.dimension, "weights": primitive.weights.tolist(),
            "amplitude_scaling": primitive.amplitude_scaling.tolist(),
            "demonstration": {"times": primitive.times.tolist(),
                              "positions": primitive.positions.tolist()},
            "fit_error": primitive.fit_error}


def read_primitive_document(document) -> Primitive:
    """The primitive of a document; ValueError naming the first field that is missing or
    wrong, or the newer version."""
    if not isinstance(document, dict) or document.get("format") != PRIMITIVE_FORMAT:
        raise ValueError(f"not a primitive (its format is not {PRIMITIVE_FORMAT!r})")
    version = document.get("version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise ValueError(f"version must be a whole number >= 1, got {version!r}")
    if version > FORMAT_VERSION:
        raise ValueError(f"version {version} is newer than this pbp_drake reads "
                         f"({FORMAT_VERSION}): update pbp_drake")
    fields = _field(document, "settings", dict)
    unknown = set(fields) - set(SETTINGS_FIELDS)
    if unknown:
        raise ValueError(f"settings has unknown fields {sorted(unknown)}")
    try:
        settings = DmpSettings(**fields)
    except (TypeError, ValueError) as error:
        raise ValueError(f"settings: {error}") from None
    dimension = _field(document, "dimension", int)
    demonstration = _field(document, "demonstration", dict)
    times = _numbers(demonstration.get("times"), "demonstration.times", 1)
    positions = _numbers(demonstration.get("positions"), "demonstration.positions", 2)
    weights = _numbers(document.get("weights"), "weights", 2)
    scaling = document.get("amplitude_scaling")
    if (not isinstance(scaling, list) or len(scaling) != dimension
            or not all(isinstance(value, bool) for value in scaling)):
        raise ValueError(f"amplitude_scaling must be {dimension} true or false values")
    if positions.shape[1] != dimension or weights.shape != (settings.basis_count, dimension):
        raise ValueError(f"weights {weights.shape} and demonstration.positions "
                         f"{positions.shape} do not fit dimension {dimension} and "
                         f"basis_count {settings.basis_count}")
    try:
        times, positions = validate_demonstration(times, positions)
    except ValueError as error:
        raise ValueError(f"demonstration: {error}") from None
    fit_error = document.get("fit_error")
    if not isinstance(fit_error, (int, float)) or not np.isfinite(fit_error) or fit_error < 0:
        raise ValueError(f"fit_error must be a finite number >= 0, got {fit_error!r}")
    return Primitive(settings, weights, np.array(scaling, bool), times, positions,
                     float(fit_error))


def _field(document, name, kind):
    value = document.get(name)
    if not isinstance(value, kind) or isinstance(value, bool):
        raise ValueError(f"{name} is missing or not {'a number' if kind is int else 'a map'}")
    return value


def _numbers(value, name, ndim):
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError):
        array = None
    if array is None or array.ndim != ndim or array.size == 0 or not np.isfinite(array).all():
        shape = "a list of numbers" if ndim == 1 else "a table of numbers (rows of equal length)"
        raise ValueError(f"{name} must be {shape}, finite")
    return array
