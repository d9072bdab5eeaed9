"""A primitive taught by driving: ONE demonstration's DMP shape, kept as a document and sent
to any goal (`pbp-drake teach` writes one; a scenario's `dmp: {primitive: FILE}` reads it).
A demonstration of poses (the grasping task's hand) also teaches an orientation shape.
`teach_primitive` fits it, `primitive_bank` carries the shape to each goal; the document
(`primitive_document`, `read_primitive_document`) is plain JSON data, its fields in
docs/tasks/teach.md, "The file"."""

import dataclasses

import numpy as np

from pbp_drake.core import quaternion
from pbp_drake.core.dmp._checks import goal_count_of
from pbp_drake.core.dmp.bank import DmpBankModel
from pbp_drake.core.dmp.fitting import fit_weights, validate_demonstration
from pbp_drake.core.dmp.orientation import (
    OrientationDmp, fit_orientation_weights, validate_orientation_demonstration)
from pbp_drake.core.dmp.orientation_bank import OrientationDmpBank
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
class OrientationShape:
    """A taught orientation shape: `weights` (N, 3), `amplitude_scaling` (3,), the
    demonstration's `quaternions` (T, 4) and `fit_error` (rad)."""

    weights: np.ndarray
    amplitude_scaling: np.ndarray
    quaternions: np.ndarray
    fit_error: float


@dataclasses.dataclass(frozen=True)
class Primitive:
    """A taught DMP shape: the fit's `settings`, `weights` (N, D), `amplitude_scaling`
    (D,), the demonstration (`times` (T,), `positions` (T, D)) and `fit_error` (m); with
    `orientation` (an `OrientationShape`) a pose's."""

    settings: DmpSettings
    weights: np.ndarray
    amplitude_scaling: np.ndarray
    times: np.ndarray
    positions: np.ndarray
    fit_error: float
    orientation: OrientationShape | None = None

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


def teach_primitive(times, positions, settings=DmpSettings(), orientations=None) -> Primitive:
    """The primitive of one demonstration `times` (T,), `positions` (T, D), and with
    `orientations` (T, 4) its poses'; ValueError when it is too short, does not move, or has
    NaN (the message says which)."""
    times, positions = check_primitive_demonstration(times, positions)
    weights, scaling = fit_weights(times, positions, settings)
    fit = _fit_error(times, positions, weights, scaling, settings)
    shape = None if orientations is None else _orientation_shape(times, orientations, settings)
    return Primitive(dataclasses.replace(settings, primitive=""), weights, scaling,
                     times - times[0], positions, fit, shape)


def check_primitive_demonstration(times, positions):
    """A primitive's demonstration `times` (T,), `positions` (T, D) as float arrays;
    ValueError when it has fewer than MIN_SAMPLES samples, ends less than MIN_TRAVEL from
    where it starts, or has NaN (the message says which)."""
    # Counted first: the demonstration check's own least (3) would be named to one of 2.
    count = np.shape(positions)[0] if np.ndim(positions) else 0
    if count < MIN_SAMPLES:
        raise ValueError(f"the demonstration has {count} samples; at least "
                         f"{MIN_SAMPLES} are needed")
    times, positions = validate_demonstration(times, positions)
    travel = float(np.linalg.norm(positions[-1] - positions[0]))
    if travel < MIN_TRAVEL:
        raise ValueError(f"the demonstration ends {travel:.3f} m from where it starts; a "
                         f"primitive needs at least {MIN_TRAVEL} m")
    return times, positions


def _orientation_shape(times, orientations, settings):
    """The orientation part of a pose demonstration: its fit, and the RMS angle (rad) of
    its orientation DMP rolled out to its own goal against it."""
    times, orientations = _named("the demonstration's orientations",
                                 validate_orientation_demonstration, times, orientations)
    weights, scaling = fit_orientation_weights(times, orientations, settings)
    duration = times[-1] - times[0]
    dmp = OrientationDmp(weights, orientations[0], orientations[-1], duration, settings,
                         scaling)
    steps = len(times) - 1
    step = duration / steps
    path = dmp.rollout(step)
    # The rollout's sample nearest each of the demonstration's times.
    nearest = np.clip(np.rint((times - times[0]) / step).astype(int), 0, steps)
    angles = quaternion.angle_between(path[nearest].T, orientations.T)
    return OrientationShape(weights, scaling, orientations,
                            float(np.sqrt(np.mean(angles ** 2))))


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
    _check_primitive(primitive, goal_count)
    return DmpBankModel(primitive.weights, start,
                        primitive.duration if duration is None else duration,
                        primitive.settings, primitive.amplitude_scaling, goal_count)


def primitive_orientation_bank(primitive: Primitive, start, goal_count,
                               duration=None) -> OrientationDmpBank:
    """`goal_count` orientation DMPs from the unit quaternion `start` with the primitive's
    orientation shape (it must have one), of `duration` (s; the demonstration's when None)."""
    shape = _check_primitive(primitive, goal_count).orientation
    if shape is None:
        raise ValueError("primitive has no orientation shape: teach it with orientations")
    return OrientationDmpBank(shape.weights, start,
                              primitive.duration if duration is None else duration,
                              primitive.settings, shape.amplitude_scaling, goal_count)


def _check_primitive(primitive, goal_count):
    """`primitive`, refused unless a `Primitive` (and `goal_count` a whole number >= 1)."""
    goal_count_of(goal_count)
    if not isinstance(primitive, Primitive):
        raise ValueError(f"primitive must be a Primitive (teach_primitive, "
                         f"read_primitive_document), got {type(primitive).__name__}")
    return primitive


def primitive_document(primitive: Primitive) -> dict:
    """The primitive as plain JSON data (docs/tasks/teach.md, "The file")."""
    orientation = primitive.orientation
    pose = {} if orientation is None else {"orientation": {
        "weights": orientation.weights.tolist(),
        "amplitude_scaling": orientation.amplitude_scaling.tolist(),
        "quaternions": orientation.quaternions.tolist(), "fit_error": orientation.fit_error}}
    return {"format": PRIMITIVE_FORMAT, "version": FORMAT_VERSION,
            "settings": {name: getattr(primitive.settings, name) for name in SETTINGS_FIELDS},
            "dimension": primitive.dimension, "weights": primitive.weights.tolist(),
            "amplitude_scaling": primitive.amplitude_scaling.tolist(),
            "demonstration": {"times": primitive.times.tolist(),
                              "positions": primitive.positions.tolist()},
            "fit_error": primitive.fit_error, **pose}


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
    # A field left out would take DmpSettings' default, not the fit's: the weights of a
    # Pastor fit read as Ijspeert's draw another shape.
    missing = [name for name in SETTINGS_FIELDS if name not in fields]
    if missing:
        raise ValueError(f"settings lacks {missing}: the fit's {', '.join(SETTINGS_FIELDS)} "
                         "are all needed (teach it again)")
    try:
        settings = DmpSettings(**fields)
    except (TypeError, ValueError) as error:
        raise ValueError(f"settings: {error}") from None
    dimension = _field(document, "dimension", int)
    demonstration = _field(document, "demonstration", dict)
    times = _numbers(demonstration.get("times"), "demonstration.times", 1)
    positions = _numbers(demonstration.get("positions"), "demonstration.positions", 2)
    weights = _numbers(document.get("weights"), "weights", 2)
    scaling = _flags(document.get("amplitude_scaling"), "amplitude_scaling", dimension)
    if positions.shape[1] != dimension or weights.shape != (settings.basis_count, dimension):
        raise ValueError(f"weights {weights.shape} and demonstration.positions "
                         f"{positions.shape} do not fit dimension {dimension} and "
                         f"basis_count {settings.basis_count}")
    times, positions = _named("demonstration", check_primitive_demonstration, times,
                              positions)
    fit_error = _fit_error_field(document, "fit_error")
    orientation = None
    if "orientation" in document:
        orientation = _read_orientation(_field(document, "orientation", dict), settings,
                                        times)
    return Primitive(settings, weights, scaling, times, positions, fit_error, orientation)


def _read_orientation(document, settings, times):
    weights = _numbers(document.get("weights"), "orientation.weights", 2)
    quaternions = _numbers(document.get("quaternions"), "orientation.quaternions", 2)
    scaling = _flags(document.get("amplitude_scaling"), "orientation.amplitude_scaling", 3)
    if weights.shape != (settings.basis_count, 3) or quaternions.shape != (len(times), 4):
        raise ValueError(f"orientation.weights {weights.shape} and orientation.quaternions "
                         f"{quaternions.shape} do not fit basis_count {settings.basis_count} "
                         f"and the demonstration's {len(times)} samples")
    _, quaternions = _named("orientation.quaternions", validate_orientation_demonstration,
                            times, quaternions)
    return OrientationShape(weights, scaling, quaternions,
                            _fit_error_field(document, "orientation.fit_error"))


def _named(name, check, *arguments):
    """`check(*arguments)`, its ValueError's message led by `name`."""
    try:
        return check(*arguments)
    except ValueError as error:
        raise ValueError(f"{name}: {error}") from None


def _fit_error_field(document, name):
    value = document.get(name.rsplit(".", 1)[-1])
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not (
            np.isfinite(value) and value >= 0):
        raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    return float(value)


def _flags(value, name, count):
    if (not isinstance(value, list) or len(value) != count
            or not all(isinstance(flag, bool) for flag in value)):
        raise ValueError(f"{name} must be {count} true or false values")
    return np.array(value, bool)


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
