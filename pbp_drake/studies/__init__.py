"""Studies: seeded trials of scenarios, their files, summaries, reports and figures.

A study folder `DIR` holds everything needed to rebuild its tables and figures:

    DIR/study.json                        the study: scenario name and hash, methods, trials, seed
    DIR/trials/<method>/seed_<seed>.json  one trial: its metrics, scene, error (the marker that
                                          the trial is done)
    DIR/trials/<method>/seed_<seed>.csv   its time series, one row per control tick
    DIR/summary.json, DIR/results.md, DIR/trials.json, DIR/fig7*.png
                                          rebuilt from the files above by `report`
    DIR/.study.lock                       flock'd while a study writes the folder

One job per module:

- `trial_files`: the trial and study files (format, paths, CSV time series, reading back)
  and the scenario hash that keeps different scenarios apart;
- `atomic_files`: every file written whole or not at all, and a disk that fails said as
  `WriteFailed` (never a trial's result);
- `folders`: which kind of study an output folder holds (a method comparison or a 2-D
  study), so neither is written into the other's folder, and its lock (one study at a
  time);
- `runners`: one trial (run, or computed without the disk) and the local process pool;
- `ray_backend`: the same trials as Ray tasks (Ray is imported only when asked for);
- `comparison`: `run_method_comparison` and `run_method_matrix`, which trials to run,
  where, then the report;
- `matrix`: the folder of every method under every pilot (`comparison.run_method_matrix`
  runs it, all pilots' trials in one pool): a study folder per pilot, its summary;
- `matrix_report`: a matrix folder's summary, method x pilot tables and figure;
- `summary`: the summary of a study folder and the one definition of the ideal alpha;
- `report`: `report(DIR)`, the summary, `results.md`, `trials.json` and the figures;
- `progress`: the text progress bar;
- `sessions`: a participant's session of a user study (its order, practice, resuming);
- `questionnaire`: the paper's two questions, their answers and `questionnaire.json`;
- `participant_report`: the report of a folder of participant folders (per-method metrics
  and answers, pairwise Wilcoxon tests with Bonferroni correction);
- `questionnaire_figure`: the paper's Fig. 8, the proportions of the answers;
- `figures`: the paper's figures (Fig. 2, 4 and 7), drawn with matplotlib;
- `toy`: the paper's 2-D studies (the alpha study and Alt vs Cont).

This package's `__init__` imports nothing, so that a worker process that imports
`runners` does not import matplotlib.
"""
