"""The contraction of distinct weights over the basis rows that matter: the same numbers as
the full product, to its rounding, in column blocks or not."""

import numpy as np
import pytest

from pbp_drake.core.dmp.contraction import WeightRows
from pbp_drake.core.dmp.settings import DmpSettings, normalized_basis


def _basis_rows(phase):
    centres, widths = DmpSettings().basis()
    phases = np.array([phase, phase * 0.999])
    return normalized_basis(phases, centres, widths).T * phases[:, None]  # (2, N)


@pytest.mark.parametrize("block_bytes", [800_000, 4_000], ids=["one block", "blocks"])
@pytest.mark.parametrize("phase", [1.0, 0.5, 0.05, 0.01, 1e-4])
def test_windowed_product_is_the_full_product(phase, block_bytes):
    rng = np.random.default_rng(3)
    weights = rng.normal(0.0, 1e3, (50, 3001))
    weights[7] *= 1e6  # a large row far from most phases must not be cut carelessly
    rows = WeightRows(weights, block_bytes)
    basis = _basis_rows(phase)
    out = np.empty((2, weights.shape[1]))
    rows.contract_into(basis, out)
    full = basis @ weights
    scale = np.abs(basis) @ np.abs(weights)  # the full product's own rounding scale
    assert np.all(np.abs(out - full) <= 1e-14 * scale)


@pytest.mark.parametrize("phase", [1.0, 0.5, 0.05, 0.01])
def test_the_window_reads_a_quarter_of_the_rows_or_fewer(phase):
    """Over the movement (phase 1 to 0.01 at t = tau). Long after it, at phases far below
    the last centre, the narrow first functions weigh as much as the last ones, and the
    window widens to all rows, exactly as it should."""
    rows = WeightRows(np.random.default_rng(4).normal(size=(50, 30)), 800_000)
    first, stop = rows.window(_basis_rows(phase))
    assert stop - first <= 12


def test_zero_weights_give_zero_shapes():
    rows = WeightRows(np.zeros((50, 10)), 800_000)
    out = np.full((2, 10), np.nan)
    rows.contract_into(_basis_rows(0.3), out)
    assert np.array_equal(out, np.zeros((2, 10)))
