"""Studies: seeded trials of scenarios, their files, summaries, reports and figures.

`comparison` runs a method comparison (`matrix`: every method under every pilot), `toy` the
paper's 2-D studies and `sessions` a participant's session of a user study; `report`,
`matrix_report` and `participant_report` rebuild their results from the files
(`trial_files`). A study folder's layout is in docs/tasks/studies.md ("The folder").

This package's `__init__` imports nothing, so that a worker process that imports
`runners` does not import matplotlib.
"""
