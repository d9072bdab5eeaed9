"""Studies: seeded trials of scenarios, their files, summaries, reports and figures.

A study folder `DIR` holds everything needed to rebuild its tables and figures:

    DIR/study.json                        the study: scenario name and hash, methods, trials, seed
    DIR/trials/<method>/seed_<seed>.json  one trial: its metrics, scene, error (the marker that
                                          the trial is done)
    DIR/trials/<method>/seed_<seed>.csv   its time series, one row per control tick
    DIR/summary.json, DIR/results.md, DIR/trials.json, DIR/fig7*.png
                                          rebuilt from the files above by `report`
    DIR/.study.lock                       flock'd while a study writes the folder

`comparison` runs a method comparison (`matrix`: every method under every pilot), `toy` the
paper's 2-D studies and `sessions` a participant's session of a user study; `report`,
`matrix_report` and `participant_report` rebuild their results from the files
(`trial_files`, written whole or not at all by `atomic_files`). Each module's docstring
says its one job.

This package's `__init__` imports nothing, so that a worker process that imports
`runners` does not import matplotlib.
"""
