"""A primitive taught from one demonstration: the fit reproduces the demonstration, the
shape goes to other goals (both formulations), the document round-trips, and bad
demonstrations and damaged documents are refused with what is wrong."""

import importlib.util
import json
import pathlib

import numpy as np
import pytest

from pbp_drake.core.dmp import DmpSettings, FORMULATIONS
from pbp_drake.core.dmp.primitive import (
    FORMAT_VERSION, primitive_bank, primitive_document, primitive_orientation_bank,
    read_primitive_document, teach_primitive)
from pbp_drake.core.quaternion import angle_between

START, GOAL = np.array([0.5, 0.0, 0.7]), np.array([1.5, 0.2, 0.7])
BEND = 0.25  # m: how high the demonstration rises over a low wall half way


def over_a_wall(samples=200, duration=4.0):
    """A reach that rises BEND above the straight line half way, as a hand lifted over a
    low wall would."""
    times = np.linspace(0.0, duration, samples)
    s = times / duration
    progress = 10 * s**3 - 15 * s**4 + 6 * s**5
    positions = START + np.outer(progress, GOAL - START)
    positions[:, 2] += BEND * np.sin(np.pi * progress)
    return times, positions


@pytest.mark.parametrize("formulation", FORMULATIONS)
def test_a_bent_demonstration_is_reproduced_and_carried_to_other_goals(formulation):
    primitive = teach_primitive(*over_a_wall(), DmpSettings(formulation=formulation))
    assert primitive.fit_error < 0.01  # within 1 cm RMS at its own goal
    goals = np.array([[1.2, -0.4, 0.7], [1.0, 0.5, 0.9], [1.8, 0.0, 0.6]])
    bank = primitive_bank(primitive, START, len(goals), 4.0)
    phase, _, velocity = bank.initial_state()
    paths = bank.predict(phase, START[:, None], velocity, bank.goals_matrix(goals), 0.01, 600)
    for goal, path in zip(goals, paths):
        assert np.linalg.norm(path[-1] - goal) < 0.01
        # Over the wall on the way to each goal, as the demonstration went.
        along = (path[:, 0] - START[0]) / (goal[0] - START[0])
        chord = START[2] + along * (goal[2] - START[2])
        assert (path[:, 2] - chord).max() > 0.8 * BEND


def test_the_document_round_trips():
    primitive = teach_primitive(*over_a_wall(), DmpSettings(formulation="pastor"))
    again = read_primitive_document(json.loads(json.dumps(primitive_document(primitive))))
    assert again.settings == primitive.settings and again.fit_error == primitive.fit_error
    np.testing.assert_array_equal(again.weights, primitive.weights)
    np.testing.assert_array_equal(again.positions, primitive.positions)


def test_a_straight_demonstration_takes_the_straight_duration():
    times = np.linspace(0.0, 2.0, 50)
    primitive = teach_primitive(times, START + np.outer(times / 2.0, GOAL - START))
    assert primitive.length_ratio == pytest.approx(1.0)
    assert teach_primitive(*over_a_wall()).length_ratio > 1.1


@pytest.mark.parametrize("times, positions, message", [
    (np.linspace(0, 1, 5), np.linspace(START, GOAL, 5), "has 5 samples; at least 10"),
    # Told "at least 3" first, then "at least 10" for 3.
    (np.linspace(0, 1, 2), np.linspace(START, GOAL, 2), "has 2 samples; at least 10"),
    (np.linspace(0, 1, 50), np.tile(START, (50, 1)) + 0.001,
     "ends 0.000 m from where it starts; a primitive needs at least 0.02 m"),
    (np.linspace(0, 1, 50), np.where(np.arange(50)[:, None] == 7, np.nan,
                                     np.linspace(START, GOAL, 50)), "NaN or infinite at sample 7"),
])
def test_a_demonstration_too_short_still_or_nan_is_refused(times, positions, message):
    with pytest.raises(ValueError, match=message):
        teach_primitive(times, positions)


def _damaged(change):
    document = primitive_document(teach_primitive(*over_a_wall()))
    change(document)
    return document


@pytest.mark.parametrize("change, message", [
    (lambda d: d.update(version=FORMAT_VERSION + 1),
     f"version {FORMAT_VERSION + 1} is newer than this pbp_drake reads"),
    (lambda d: d.update(format="something else"), "not a primitive"),
    (lambda d: d.pop("weights"), "weights must be a table of numbers"),
    (lambda d: d["weights"][3].__setitem__(1, float("nan")), "weights must be"),
    (lambda d: d["weights"].pop(), r"weights \(49, 3\) .* do not fit"),
    (lambda d: d["settings"].update(formulation="spline"), "settings: formulation 'spline'"),
    (lambda d: d.update(amplitude_scaling=[True]), "amplitude_scaling must be 3"),
    (lambda d: d.update(fit_error=-1), "fit_error must be a finite number >= 0"),
    (lambda d: d.update(version="1"), "version must be a whole number >= 1, got '1'"),
    (lambda d: d["settings"].update(alpha=1.0), r"settings has unknown fields \['alpha'\]"),
    (lambda d: d.update(settings=[]), "settings is missing or not a map"),
    # Read as the defaults, a Pastor fit's weights ran as Ijspeert's.
    (lambda d: d["settings"].pop("formulation"), r"settings lacks \['formulation'\]"),
    (lambda d: d.update(settings={}), r"settings lacks \['formulation', 'basis_count', "),
    (lambda d: d.pop("dimension"), "dimension is missing or not a number"),
    (lambda d: d["weights"][3].pop(), "weights must be a table of numbers"),
    (lambda d: d["demonstration"]["times"].reverse(),
     "demonstration: demonstration times must be finite and strictly increasing"),
    # As teach_primitive refuses them: the bank's duration was infinite, or NaN.
    (lambda d: d["demonstration"]["positions"].__setitem__(-1, d["demonstration"]["positions"][0]),
     "demonstration: the demonstration ends 0.000 m from where it starts"),
    (lambda d: d.update(demonstration={key: value[:5] for key, value
                                       in d["demonstration"].items()}),
     "demonstration: the demonstration has 5 samples; at least 10"),
])
def test_a_damaged_document_is_refused_naming_the_field(change, message):
    with pytest.raises(ValueError, match=message):
        read_primitive_document(_damaged(change))


def test_the_shipped_wall_primitive_is_its_scripted_demonstration_taught():
    # diagrams/primitives/around_the_wall.py writes the demonstration; `pbp-drake teach
    # --from` it wrote the JSON. The demonstration within 1e-12 m of the script's, the fit
    # within 1e-9 of one made now: NumPy's exp and sums may differ in their last bits from
    # one version or CPU to another.
    folder = pathlib.Path(__file__).resolve().parents[2] / "diagrams" / "primitives"
    spec = importlib.util.spec_from_file_location("around_the_wall", folder / "around_the_wall.py")
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    times, positions = script.demonstration()
    recorded = np.loadtxt(folder / "around_the_wall.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(recorded, np.column_stack([times, positions]), rtol=0, atol=1e-12)
    shipped = read_primitive_document(json.loads((folder / "around_the_wall.json").read_text()))
    now = teach_primitive(times, positions, shipped.settings)
    assert shipped.settings == DmpSettings(formulation="pastor")
    np.testing.assert_allclose(shipped.weights, now.weights, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(shipped.positions, positions, rtol=0, atol=1e-12)
    assert shipped.fit_error == pytest.approx(now.fit_error, rel=1e-9) and now.fit_error < 0.01


def turning_while_reaching(samples=200, duration=4.0):
    """The wall's reach, the hand turning 90 degrees about z and tipping 30 degrees on the
    way (a grasp from above): times, positions and unit quaternions (w, x, y, z)."""
    times, positions = over_a_wall(samples, duration)
    s = times / duration
    progress = 10 * s**3 - 15 * s**4 + 6 * s**5  # from rest to rest, as the reach
    yaw, tip = np.pi / 2 * progress, np.radians(30) * np.sin(np.pi * progress)
    about_z = np.column_stack([np.cos(yaw / 2), 0 * s, 0 * s, np.sin(yaw / 2)])
    about_x = np.column_stack([np.cos(tip / 2), np.sin(tip / 2), 0 * s, 0 * s])
    w1, v1 = about_z[:, :1], about_z[:, 1:]
    w2, v2 = about_x[:, :1], about_x[:, 1:]
    product = np.column_stack([w1 * w2 - np.sum(v1 * v2, axis=1, keepdims=True),
                               w1 * v2 + w2 * v1 + np.cross(v1, v2)])
    return times, positions, product


@pytest.mark.parametrize("formulation", FORMULATIONS)
def test_a_pose_demonstration_teaches_its_turn_too(formulation):
    times, positions, orientations = turning_while_reaching()
    primitive = teach_primitive(times, positions, DmpSettings(formulation=formulation),
                                orientations)
    assert primitive.fit_error < 0.01 and primitive.orientation.fit_error < np.radians(1.0)
    again = read_primitive_document(json.loads(json.dumps(primitive_document(primitive))))
    np.testing.assert_array_equal(again.orientation.weights, primitive.orientation.weights)
    assert again.orientation.fit_error == primitive.orientation.fit_error
    # Sent to another final orientation, the bank ends there.
    goal = orientations[-1][[0, 3, 2, 1]] * [1, 1, 1, -1]
    goal /= np.linalg.norm(goal)
    bank = primitive_orientation_bank(primitive, orientations[0], 1, 4.0)
    phase, orientation, velocity = bank.initial_state()
    paths = bank.predict(phase, orientation, velocity, goal[:, None], 0.01, 600)
    assert angle_between(paths[0][-1], goal) < np.radians(1.0)


def test_a_damaged_orientation_is_refused_naming_the_field():
    times, positions, orientations = turning_while_reaching()
    document = primitive_document(teach_primitive(times, positions, DmpSettings(),
                                                  orientations))
    document["orientation"]["quaternions"].pop()
    with pytest.raises(ValueError, match=r"orientation.weights \(50, 3\) and "
                                         r"orientation.quaternions \(199, 4\) do not fit"):
        read_primitive_document(document)


@pytest.mark.parametrize("build, message", [
    (lambda: primitive_bank(None, START, 3), r"primitive must be a Primitive \(teach_primitive, "
                                            r"read_primitive_document\), got NoneType"),
    (lambda: primitive_orientation_bank("wall.json", [1.0, 0.0, 0.0, 0.0], 3),
     "primitive must be a Primitive .* got str"),
    (lambda: primitive_bank(teach_primitive(*over_a_wall()), START, None),
     "goal_count must be an integer >= 1, got None"),
    (lambda: primitive_bank(teach_primitive(*over_a_wall()), START, 2.5),
     "goal_count must be an integer >= 1, got 2.5"),
    (lambda: primitive_orientation_bank(teach_primitive(*over_a_wall()), [1.0, 0.0, 0.0, 0.0],
                                        3), "primitive has no orientation shape"),
])
def test_a_bank_of_what_is_no_primitive_is_refused_naming_it(build, message):
    with pytest.raises(ValueError, match=message):
        build()
