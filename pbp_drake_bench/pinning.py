"""BLAS threads pinned without any optional package: the bench measures in a fresh Python
process whose thread variables (OPENBLAS_NUM_THREADS, OMP_NUM_THREADS, MKL_NUM_THREADS, ...)
are set before NumPy is first imported, the only time OpenBLAS, MKL and BLIS read them.

`pbp-drake bench` cannot set them in its own process: `pbp_drake.cli` (and this package)
import NumPy before the bench's arguments are read. So the bench's entry starts this fresh
process (`measure_in_fresh_process`), marked by `MARKER`, and the measuring process reads
back what it got (`blas_threads`): the variables as it sees them and the thread count the
loaded BLAS library reports (through threadpoolctl when installed, else OpenBLAS's own
`openblas_get_num_threads` found with ctypes).

No NumPy import here: the parent process must not need one to start the child.
"""

import ctypes
import os
import subprocess
import sys
from pathlib import Path

THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                    "BLIS_NUM_THREADS", "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS")
# Set in the measuring process's environment, to the threads asked for, by its parent.
MARKER = "PBP_DRAKE_BENCH_BLAS_THREADS"
# The folder holding the `pbp_drake_bench` package this file belongs to: the child imports
# the same code, whatever its working directory holds.
PACKAGE_ROOT = str(Path(__file__).resolve().parents[1])
_CHILD = ("import sys; sys.path[0] = sys.argv.pop(1); "
          "from pbp_drake_bench.main import main; sys.exit(main(sys.argv[1:]))")
# OpenBLAS's thread-count getter under the names its builds export (NumPy's wheels bundle
# scipy-openblas, whose symbols carry a prefix and a 64-bit-integer suffix).
_OPENBLAS_GETTERS = ("openblas_get_num_threads", "openblas_get_num_threads64_",
                     "scipy_openblas_get_num_threads64_", "scipy_openblas_get_num_threads")


def pinned_environment(threads, environment=None):
    """A copy of `environment` (default: this process's) with every thread variable and
    the marker set to `threads`."""
    pinned = dict(os.environ if environment is None else environment)
    for name in THREAD_VARIABLES:
        pinned[name] = str(threads)
    pinned[MARKER] = str(threads)
    return pinned


def in_measuring_process():
    """Whether this process was started pinned by `measure_in_fresh_process`."""
    return MARKER in os.environ


def measure_in_fresh_process(argv, threads):
    """Runs the bench with `argv` in a fresh Python process whose thread variables are
    `threads` from its start; returns its exit code (1 if a signal ended it)."""
    command = [sys.executable, "-c", _CHILD, PACKAGE_ROOT, *argv]
    try:
        completed = subprocess.run(command, env=pinned_environment(threads), check=False)
    except KeyboardInterrupt:
        return 130
    return completed.returncode if completed.returncode >= 0 else 1


def blas_threads(requested):
    """What this process runs BLAS with: a dict for bench.json, whose "note" is the header's
    sentence. `requested` 0 means the library's default (nothing pinned)."""
    variables = {name: os.environ.get(name) for name in THREAD_VARIABLES}
    library, reported = _library_threads()
    pinned = requested > 0 and os.environ.get(MARKER) == str(requested) and all(
        value == str(requested) for value in variables.values())
    reads = (f"{library} reports {reported}" if reported is not None
             else "the BLAS library's own count could not be read")
    if requested <= 0:
        note = f"BLAS threads: library default, not pinned ({reads})"
    elif pinned:
        note = (f"BLAS threads: {requested} ({', '.join(THREAD_VARIABLES[:3])} and the "
                f"others set to {requested} before NumPy loaded; {reads})")
    else:
        note = (f"BLAS threads: NOT pinned to {requested} (this process was not started "
                f"with the thread variables set; {reads})")
    return {"requested": requested, "pinned_before_numpy": pinned, "variables": variables,
            "library": library, "library_threads": reported, "note": note}


def _library_threads():
    """(name, threads) of the BLAS library loaded in this process, or (None, None)."""
    try:
        # Deferred on purpose: threadpoolctl is optional (pip install -e '.[bench]').
        from threadpoolctl import threadpool_info
    except ImportError:
        return _openblas_threads()
    blas = [pool for pool in threadpool_info() if pool.get("user_api") == "blas"]
    if not blas:
        return None, None
    return f"{blas[0]['internal_api']} (threadpoolctl)", blas[0]["num_threads"]


def _openblas_threads():
    """OpenBLAS's own thread count, through ctypes, for the libraries this process has
    mapped (Linux's /proc/self/maps); (None, None) where that cannot be read."""
    try:
        with open("/proc/self/maps") as maps:
            paths = sorted({line.split()[-1] for line in maps
                            if "openblas" in line.lower() and line.split()[-1].startswith("/")})
    except OSError:
        return None, None
    for path in paths:
        try:
            library = ctypes.CDLL(path)
        except OSError:
            continue
        for getter in _OPENBLAS_GETTERS:
            function = getattr(library, getter, None)
            if function is not None:
                function.restype = ctypes.c_int
                return f"openblas ({getter})", int(function())
    return None, None
