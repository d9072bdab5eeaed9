"""Timing: the median of repeated calls, and this machine's memory bandwidth (the bound on
streaming distinct weights). BLAS threads are pinned before NumPy loads (`pinning`)."""

import time

import numpy as np


def timed(step, min_time, max_repeats=5000, min_repeats=3, warmup=2):
    """Median and minimum seconds of `step()`, repeated for at least `min_time` seconds."""
    for _ in range(warmup):
        step()
    samples = []
    began = time.perf_counter()
    while len(samples) < max_repeats and (
            len(samples) < min_repeats or time.perf_counter() - began < min_time):
        start = time.perf_counter()
        step()
        samples.append(time.perf_counter() - start)
    samples = np.array(samples)
    return float(np.median(samples)), float(samples.min()), len(samples)


def timed_span(step, done, stretches=8):
    """Seconds of `step()` repeated until `done()`: the median, the largest median of
    `stretches` equal consecutive stretches of the repeats (for a step whose cost moves
    along the run), and the number of repeats."""
    samples = []
    while not done():
        start = time.perf_counter()
        step()
        samples.append(time.perf_counter() - start)
    slowest = max(float(np.median(part)) for part in np.array_split(
        np.array(samples), min(stretches, len(samples))))
    return float(np.median(samples)), slowest, len(samples)


def memory_bandwidth(megabytes=400, cache_megabytes=12, repeats=5):
    """GB/s of a NumPy sum (read) and copy (read + write) of a large array, and of a sum of
    an array the size of the weights of K = 10,000, D = 3 (which may stay in cache)."""
    n = int(megabytes * 1e6 / 8)
    a = np.ones(n)
    b = np.empty(n)
    a.sum()
    np.copyto(b, a)
    sum_time = min(_clock(a.sum) for _ in range(repeats))
    copy_time = min(_clock(lambda: np.copyto(b, a)) for _ in range(repeats))
    a = b = None  # the arrays go before the next case is measured
    small = np.ones(int(cache_megabytes * 1e6 / 8))
    cache_time = timed(small.sum, 0.2, max_repeats=200)[1]
    return {
        "array_megabytes": megabytes,
        "read_gb_per_s": megabytes * 1e6 / sum_time / 1e9,
        "copy_gb_per_s": 2 * megabytes * 1e6 / copy_time / 1e9,
        "cache_array_megabytes": cache_megabytes,
        "cache_read_gb_per_s": cache_megabytes * 1e6 / cache_time / 1e9,
    }


def _clock(function):
    start = time.perf_counter()
    function()
    return time.perf_counter() - start
