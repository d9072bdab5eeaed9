"""The contraction of distinct weights with the basis, `(2, N) x (N, M)`, reading only the
basis rows that matter at the step's phase: shared by the position and orientation banks.

At any phase only a few neighbouring functions of the normalised basis are not nearly zero
(5 to 12 of the default 50), and the weights are laid out `(N, M)`, so those rows are one
contiguous slice. A row is left out only when the largest term it could add to any column,
`max_r |b_rn| max_m |W_nm|`, is below `2^-53 / N` of the largest such bound over the rows,
or below `2^-53 / N` itself: the rows left out then add, together, less than one rounding
unit of the largest term, or less than `2^-53` in the weights' units (per unit of
amplitude). Why the second bound: docs/concepts/dmp.md, "Orientation DMPs"."""

import numpy as np

# The most the left-out rows may add, over the largest row's bound (or absolutely), per row.
_RELATIVE_PER_ROW = 2.0 ** -53
# The product runs in blocks of columns holding about this many bytes of weights (they fit
# the L2 cache): OpenBLAS's one long two-row dgemm took up to twice a one-row dgemv; in
# blocks it takes what the dgemv takes.
BLOCK_BYTES = 800_000


class WeightRows:
    """Distinct weights `(N, M)` (read-only, C order) prepared for `contract_into`: each
    row's largest magnitude, and column blocks of about `block_bytes` (`BLOCK_BYTES`)."""

    __slots__ = ("weights", "row_bounds", "block_bytes")

    def __init__(self, weights, block_bytes=BLOCK_BYTES):
        self.weights = weights
        bounds = np.abs(weights).max(axis=1)
        bounds.setflags(write=False)
        self.row_bounds = bounds
        self.block_bytes = block_bytes

    def window(self, basis):
        """`(first, stop)`: the rows of the basis `(2, N)` whose terms can matter (module
        docstring); at least one row."""
        # Two rows, written out: the reductions' wrappers cost more than the arithmetic.
        bounds = np.maximum(np.abs(basis[0]), np.abs(basis[1]))
        bounds *= self.row_bounds
        largest = np.maximum.reduce(bounds)
        floor = max(largest, 1.0) * (_RELATIVE_PER_ROW / bounds.size)
        kept = (bounds >= floor).nonzero()[0]
        if kept.size == 0:
            first = int(np.argmax(bounds))  # every term is below 2^-53 / N: the largest
            return first, first + 1
        return int(kept[0]), int(kept[-1]) + 1

    def contract_into(self, basis, out, weights=None, window=None):
        """`out = basis @ weights` `(2, M)` over the rows that matter (`window`, or the
        one given); `weights`: another `(N, M)` array to contract in place of this one's
        (the orientation bank's, multiplied by the goals' amplitudes), over the same rows."""
        first, stop = self.window(basis) if window is None else window
        basis = basis[:, first:stop]
        weights = (self.weights if weights is None else weights)[first:stop]
        rows, columns = weights.shape
        # Fewer rows, wider blocks: each block keeps about `block_bytes` of weights.
        width = max(64, self.block_bytes // weights.itemsize // rows)
        blocks = columns // width
        if blocks <= 1:
            np.dot(basis, weights, out=out)
            return
        covered = blocks * width
        np.matmul(basis, weights[:, :covered].reshape(rows, blocks, width).transpose(1, 0, 2),
                  out=out[:, :covered].reshape(2, blocks, width).transpose(1, 0, 2))
        np.matmul(basis, weights[:, covered:], out=out[:, covered:])


def scaled_weights(weights, workspace, first, stop):
    """Distinct weights `(N, M)` times the goals' amplitudes (the workspace's `amplitude`,
    flattened as the weights' columns), valid in rows `first:stop`: kept in the workspace
    (`scaled_weights`, allocated on first use) and scaled row by row when first needed
    since the amplitudes last changed (`scaled_rows`, which whoever changes them clears).
    The window moves one row every hundred steps or so; the contraction then gives the
    Ijspeert attractor's part `S * amplitude` at once (one rounding per term more, as the
    pass over `S` it saves)."""
    ws = workspace
    if ws.scaled_weights is None or ws.scaled_weights.shape != weights.shape:
        ws.scaled_weights = np.empty_like(weights)
        ws.scaled_rows = np.zeros(len(weights), bool)
    rows = ws.scaled_rows[first:stop]
    if not rows.all():
        amplitude = ws.amplitude.reshape(-1)
        for index in np.flatnonzero(~rows) + first:
            np.multiply(weights[index], amplitude, out=ws.scaled_weights[index])
        rows[...] = True
    return ws.scaled_weights
