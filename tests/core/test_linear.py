"""The small closed-form matrix exponential (pbp_drake.core.linear) against SciPy's."""

import numpy as np
import pytest
from scipy.linalg import expm as scipy_expm

from pbp_drake.core.linear import expm


@pytest.mark.parametrize("matrix", [
    np.zeros((2, 2)),
    [[0.0, 1.0], [-400.0, -40.0]],  # the point robot's A at its default gains
    [[-3.0, 2.0, 0.0, 0.5], [0.0, -1.0, 4.0, 0.0], [1.0, 0.0, -2.0, 0.0], [0.0, 0.0, 0.0, 0.1]],
])
def test_expm_is_scipys_to_rounding(matrix):
    np.testing.assert_allclose(expm(matrix), scipy_expm(np.asarray(matrix)), rtol=1e-12,
                               atol=1e-14)


def test_expm_refuses_a_matrix_that_is_not_square():
    with pytest.raises(ValueError, match=r"expm needs a square matrix, got shape \(2, 3\)"):
        expm(np.zeros((2, 3)))
