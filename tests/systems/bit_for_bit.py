"""What the compact-state tests assert: two runs' outputs equal bit for bit."""

import numpy as np


def assert_same_outputs(expected_run, run, names):
    """Every read of `run` (a list of output lists, named `names`) equals `expected_run`'s
    bit for bit; the message names the first output and read that differ."""
    assert len(expected_run) == len(run)
    for read, (expected, got) in enumerate(zip(expected_run, run)):
        for name, a, b in zip(names, expected, got):
            assert np.array_equal(a, b), f"{name} differs at read {read}"
