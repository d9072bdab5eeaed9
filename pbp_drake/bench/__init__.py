"""`pbp-drake bench`: how fast the DMP bank steps, beside the libraries people use today.

Measured in one run on this machine (issue 6):

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

Writes `bench.json` and the figure into `--output` (default `outputs/bench`). Timings are
medians over repeats (the repeat count adapts to K); BLAS is limited to `--blas-threads`
(default 1, through threadpoolctl when installed) for every backend alike.

Modules: `timing` (the timer, BLAS pinning, memory bandwidth), `cases` (the banks and the
steps timed), `peers` (pydmps and movement_primitives), `closed_loop` (the HSR task's
speed), `report` (the table and the acceptance checks), `plot` (the control-rate figure),
`run` (the command line; `python -m pbp_drake.bench`).
"""
