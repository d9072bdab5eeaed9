"""`vector_length` is numpy's norm of a vector, the same number bit for bit: the task
monitor's success test and the hand-over's speed limit read it every tick."""

import numpy as np
import pytest

from pbp_drake.core.coordinates import vector_length


@pytest.mark.parametrize("size", [1, 2, 3, 6, 9])
def test_is_numpys_norm_bit_for_bit(size):
    rng = np.random.default_rng(size)
    for scale in (1e-300, 1e-9, 1.0, 1e6, 1e150):
        vector = rng.normal(size=size) * scale
        assert vector_length(vector) == float(np.linalg.norm(vector))
    assert vector_length(np.zeros(size)) == 0.0
    assert vector_length([3, 4] if size == 2 else np.arange(size)) == float(
        np.linalg.norm([3, 4] if size == 2 else np.arange(size)))


def test_overflows_and_propagates_nan_as_numpy_does():
    with np.errstate(over="ignore"):
        assert vector_length([1e200, 1e200]) == float(np.linalg.norm([1e200, 1e200])) == np.inf
    assert np.isnan(vector_length([np.nan, 1.0]))
