"""`pbp-drake bench`: how fast the DMP bank steps, beside the libraries people use today.

Measured in one run, on the machine it runs on:

- this machine's memory bandwidth (a NumPy copy and sum of a large array, and a sum of a
  cache-sized one), the bound it puts on streaming distinct weights;
- the DMP bank's step for K goals and D dimensions (50 basis functions), with distinct
  learned weights per goal and with one demonstration shared by all goals: the bank math
  alone (`DmpBank.advance_into`) and inside its Drake `LeafSystem` (a Simulator stepping it
  at 1 kHz from constant inputs), with Drake's event overhead measured separately (the same
  LeafSystem ports and state, an update that does nothing);
- the same step with `pydmps` and `movement_primitives`, one object per goal as their APIs
  intend, re-integrated from the robot's position as PBP does, and `movement_primitives`
  with all goals stacked into one K*D-dimensional DMP;
- closed loop: simulated seconds per wall second of the HSR reaching task with K goals,
  headless and with Meshcat publishing;
- the control rate reached versus K, as a figure (`bench_control_rate.png`).

Writes `bench.json`, `bench.txt` and the figure into `--output` (default `outputs/bench`).
Timings are medians over repeats (the repeat count adapts to K). BLAS runs `--blas-threads`
threads (default 1) for every backend alike, pinned without any optional package: the bench
measures in a fresh Python process whose OPENBLAS_NUM_THREADS, OMP_NUM_THREADS,
MKL_NUM_THREADS, ... are set before NumPy loads, and its header says what the BLAS library
reports. Each check is named for what it measures; a check whose peer library is not
installed is skipped (neither a pass nor a failure); the exit code is 1 when any check
fails, else 0. `--quick` runs the same checks at fewer repeats.

Modules: `pinning` (the fresh, pinned process), `timing` (the timer, memory bandwidth),
`cases` (the banks and the steps timed), `peers` (pydmps and movement_primitives),
`closed_loop` (the HSR task's speed), `checks` (the checks, their verdicts and the exit
code), `report` (the table), `plot` (the control-rate figure), `run` (the command line;
`python -m pbp_drake.bench`).
"""
