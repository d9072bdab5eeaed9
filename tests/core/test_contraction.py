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


@pytest.mark.parametrize("phase", [1.0, 0.5, 0.05, 0.01, 1e-3, 1e-6, 1e-8])
def test_the_window_reads_a_quarter_of_the_rows_or_fewer(phase):
    """Over the movement (phase 1 to 0.01 at t = tau) and long after it (1e-6 at 3 tau):
    at phases far below the last centre every function is a nearly equal tiny share, so
    relative to the largest term every row matters, but all but the last few add less than
    2^-53, and the window must not read every row then. (Between, near phase 1e-4 at
    2 tau, rows of 1e-17 are still kept with a fit's weights: the window widens there.)
    The basis as the Ijspeert bank contracts it, over the stiffness; a fit's weights."""
    weights = np.random.default_rng(4).normal(0.0, 1e3, (50, 30))
    rows = WeightRows(weights, 800_000)
    basis = _basis_rows(phase) / DmpSettings().stiffness
    first, stop = rows.window(basis)
    assert stop - first <= 12
    out = np.empty((2, 30))
    rows.contract_into(basis, out)
    full = basis @ weights
    assert np.all(np.abs(out - full) <= 2.0 ** -53 + 1e-15 * np.abs(full))


def test_zero_weights_give_zero_shapes():
    rows = WeightRows(np.zeros((50, 10)), 800_000)
    out = np.full((2, 10), np.nan)
    rows.contract_into(_basis_rows(0.3), out)
    assert np.array_equal(out, np.zeros((2, 10)))
