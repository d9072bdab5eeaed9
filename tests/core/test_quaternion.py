"""The unit-quaternion math (pbp_drake.core.quaternion) against SciPy's `Rotation`, finite
differences, and the antipodal rule; its input check."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from pbp_drake.core import quaternion

ANGLES_NEAR_HALF_TURN = [np.pi - 1e-3, np.pi - 1e-9, np.pi]


def wxyz(rotation):
    """SciPy's scalar-last quaternions as our `(4, K)` columns (w, x, y, z)."""
    return np.roll(np.atleast_2d(rotation.as_quat()), 1, axis=1).T


def as_rotation(columns):
    return Rotation.from_quat(np.roll(np.atleast_2d(np.asarray(columns).T), -1, axis=1))


def random_rotation_vectors(rng, count, largest=np.pi):
    """Rotation vectors with angles spread over [0, largest], the small and the half turn
    included."""
    axes = rng.normal(size=(3, count))
    axes /= np.linalg.norm(axes, axis=0)
    angles = rng.uniform(0.0, largest, count)
    angles[:5] = [0.0, 1e-12, 1e-5, 5e-3, largest]
    return axes * angles


@pytest.mark.slow
def test_product_log_exp_and_slerp_match_scipy():
    first, second = Rotation.random(50, random_state=1), Rotation.random(50, random_state=2)
    product = quaternion.multiply(wxyz(first), wxyz(second))
    assert (as_rotation(product) * (first * second).inv()).magnitude().max() < 1e-14
    np.testing.assert_allclose(quaternion.log_map(wxyz(first)), first.as_rotvec().T,
                               atol=1e-14)
    rng = np.random.default_rng(3)
    vectors = random_rotation_vectors(rng, 50)
    exact = Rotation.from_rotvec(vectors.T)
    assert (as_rotation(quaternion.exp_map(vectors)) * exact.inv()).magnitude().max() < 1e-14
    np.testing.assert_allclose(quaternion.angle_between(wxyz(first), wxyz(second)),
                               (first * second.inv()).magnitude(), atol=1e-13)
    for fraction in (0.0, 0.3, 1.0):
        ours = quaternion.slerp(wxyz(first), wxyz(second), fraction)
        theirs = Rotation.concatenate([Slerp([0, 1], Rotation.concatenate([a, b]))(fraction)
                                       for a, b in zip(first, second)])
        assert (as_rotation(ours) * theirs.inv()).magnitude().max() < 1e-12


def test_log_is_the_inverse_of_exp_up_to_half_a_turn():
    vectors = random_rotation_vectors(np.random.default_rng(4), 200, largest=np.pi - 1e-9)
    np.testing.assert_allclose(quaternion.log_map(quaternion.exp_map(vectors)), vectors,
                               atol=1e-12)


def test_antipodal_quaternions_have_the_same_log_bit_for_bit():
    """`q` and `-q` give the same rotation vector, at exactly 180 degrees too (w = 0), where
    the sign is settled on x, then y, then z."""
    vectors = random_rotation_vectors(np.random.default_rng(5), 100)
    half_turns = np.array([[1.0, 0, 0], [0, 1, 0], [0, 0, -1], [0.6, -0.8, 0], [0, 0.6, 0.8]])
    columns = np.concatenate([quaternion.exp_map(vectors),
                              np.vstack([np.zeros(5), half_turns.T])], axis=1)
    assert (columns[0, -5:] == 0.0).all()
    np.testing.assert_array_equal(quaternion.log_map(columns), quaternion.log_map(-columns))
    angles = np.linalg.norm(quaternion.log_map(columns[:, -5:]), axis=0)
    np.testing.assert_allclose(angles, np.pi, rtol=1e-15)


def test_left_jacobian_turns_log_rates_into_world_angular_velocity():
    """`omega = J(r) dr/dt` against a central difference of `Exp(r(t))`, small angles and
    half turns included, and `J^-1` undoes `J`."""
    rng = np.random.default_rng(6)
    vectors = random_rotation_vectors(rng, 100, largest=np.pi - 1e-6)
    vectors[:, -3:] = [[0, 0, np.pi - 1e-6], [0, 2.0, 0], [1e-3, 0, 0]]
    rates = rng.normal(size=(3, 100))
    step = 1e-6
    ahead, behind = (quaternion.exp_map(vectors + sign * step * rates) for sign in (1, -1))
    numerical = quaternion.log_map(quaternion.multiply(ahead, quaternion.conjugate(behind)))
    numerical /= 2 * step
    np.testing.assert_allclose(quaternion.left_jacobian_times(vectors, rates), numerical,
                               atol=1e-8)
    roundtrip = quaternion.left_jacobian_inverse_times(
        vectors, quaternion.left_jacobian_times(vectors, rates))
    np.testing.assert_allclose(roundtrip, rates, atol=1e-12)


@pytest.mark.parametrize("angle", [0.0, 1e-7, 9.99e-3, 1.001e-2, 1.0] + ANGLES_NEAR_HALF_TURN)
def test_jacobian_series_and_closed_forms_agree_at_the_switch(angle):
    """Against the matrix exponential definition, via SciPy, at angles on both sides of
    `SERIES_BELOW` and near the half turn."""
    axis = np.array([0.36, -0.48, 0.8])
    vector = axis * angle
    rates = np.eye(3)
    omega = quaternion.left_jacobian_times(vector[:, None], rates)
    # J = sum_k ad^k / (k + 1)!, the left Jacobian's series, summed far enough.
    skew = np.array([[0, -vector[2], vector[1]], [vector[2], 0, -vector[0]],
                     [-vector[1], vector[0], 0]])
    expected, term = np.zeros((3, 3)), np.eye(3)
    for k in range(60):
        expected += term
        term = term @ skew / (k + 2)
    np.testing.assert_allclose(omega, expected, atol=1e-14)
    np.testing.assert_allclose(quaternion.left_jacobian_inverse_times(vector[:, None], omega),
                               rates, atol=1e-12)


def test_unit_quaternions_are_normalised_within_the_tolerance_and_bad_ones_named():
    near = np.array([[1.0 + 0.9 * quaternion.UNIT_TOLERANCE, 0, 0, 0], [0, 0.6, 0.8, 0]])
    np.testing.assert_allclose(np.linalg.norm(quaternion.unit_quaternions(near, "goals"),
                                              axis=1), 1.0, rtol=1e-15)
    with pytest.raises(ValueError, match=r"goals is not a unit quaternion \(w, x, y, z\): "
                                         r"quaternion 1 .* has norm 1.1"):
        quaternion.unit_quaternions([[1.0, 0, 0, 0], [1.1, 0, 0, 0]], "goals")
    with pytest.raises(ValueError, match="start contains NaN or infinite values"):
        quaternion.unit_quaternions([np.nan, 1.0, 0, 0], "start")
    with pytest.raises(ValueError, match=r"start must be quaternions .* shape \(3,\)"):
        quaternion.unit_quaternions([1.0, 0, 0], "start")


@pytest.mark.slow
def test_exp_times_aligned_is_the_vectorised_composition_bit_for_bit():
    rng = np.random.default_rng(7)
    cases = [(np.zeros(3), quaternion.IDENTITY, quaternion.IDENTITY)]  # angle 0: sinc's 1e-20
    for _ in range(2000):
        q = rng.normal(size=4)
        reference = rng.normal(size=4)
        cases.append((rng.normal(scale=rng.choice([1e-9, 0.1, 1.0, 3.0]), size=3),
                      q / np.linalg.norm(q), reference / np.linalg.norm(reference)))
    flipped = 0
    for rotation_vector, q, reference in cases:
        expected = quaternion.aligned(quaternion.multiply(quaternion.exp_map(rotation_vector), q),
                                      reference)
        got = np.array(quaternion.exp_times_aligned_values(
            rotation_vector.tolist(), q.tolist(), reference.tolist()))
        assert np.array_equal(got, expected), (rotation_vector, q, reference)
        flipped += np.array_equal(got, -quaternion.multiply(quaternion.exp_map(rotation_vector), q))
    assert 500 < flipped < 1500  # both hemispheres were taken
