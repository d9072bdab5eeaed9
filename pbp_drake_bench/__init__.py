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
- closed loop: simulated seconds per wall second of the HSR reaching and grasping tasks
  with K goals (4 to 10,000), headless and with Meshcat drawing to a client (another
  process) that reads everything sent, with the bytes and messages it received per
  simulated second; where a reach tick's wall time goes by category (the DMP bank, the
  estimator, the blender, the diff IK, the drawing, the operator, the rest), from a
  cProfile run; and the size of a recorded replay at K = 4 and 1,000;
- the control rate reached versus K, and the closed loop's real-time factor versus K, as
  figures (`bench_control_rate.png`, `bench_scaling.png`).

Writes `bench.json`, `bench.txt` and the figures into `--output` (default `outputs/bench`).
Timings are medians over repeats (the repeat count adapts to K). BLAS runs `--blas-threads`
threads (default 1) for every backend alike, pinned without any optional package: the bench
measures in a fresh Python process whose OPENBLAS_NUM_THREADS, OMP_NUM_THREADS,
MKL_NUM_THREADS, ... are set before NumPy loads, and its header says what the BLAS library
reports. Each check is named for what it measures; a check whose peer library is not
installed is skipped (neither a pass nor a failure); the exit code is 1 when any check
fails, else 0. `--quick` runs the same checks at fewer repeats.

Modules: `pinning` (the fresh, pinned process), `timing` (the timer, memory bandwidth),
`cases` (the banks and the steps timed), `peers` (pydmps and movement_primitives),
`scenes` (the closed loop's reach and grasp scenes with K goals), `closed_loop` (their
speed, headless and with Meshcat), `ws_reader` (the Meshcat client that counts what it
reads), `time_split` (a tick's time by category, from cProfile), `replay` (the recorded
replay's size), `checks` (the checks, their verdicts and the exit code), `table` (the
report), `plot` (the figures), `main` (the command line; `python -m pbp_drake_bench`).

Beside the bench, the rest of the harness the library never imports: `soak` (`make soak`),
`results_catalogue` (`make results`: every study the docs quote, and the pages made from
them by `arena_page` and `many_goals_figure`) and `runaway` (runaway confidence measured
on a scripted operator).
"""
