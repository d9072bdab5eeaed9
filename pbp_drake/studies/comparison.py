"""Comparing methods on the same seeded HSR scenes: `pbp-drake study diagrams/hsr_reach.yaml`
(`run_method_comparison`), and every method under every pilot (`run_method_matrix`: a study
folder per pilot, all their trials in one pool). Each holds its folders' locks
(`folders.study_lock`) all along: one study at a time writes a folder.
"""

import contextlib
import dataclasses
import pathlib
import pickle
import sys
import time

from pbp_drake.scenarios import ScenarioError
from pbp_drake.studies.atomic_files import remove_leftovers
from pbp_drake.studies.ray_backend import import_ray, run_on_ray
from pbp_drake.studies.report import report
from pbp_drake.studies.runners import failed_record, run_locally
from pbp_drake.studies.trial_files import (
    StudyFolderError, name_damaged, read_trial, running_marker, scenario_hash, trials_left_out,
    write_study)
from pbp_drake.studies.folders import MATRIX, check_folder, study_lock
from pbp_drake.studies.matrix import check_pilots, pilot_folder, write_matrix_study
from pbp_drake.studies.matrix_report import report_matrix
from pbp_drake.scenarios.pilots import with_pilot

BACKENDS = ("local", "ray")


def run_method_comparison(scenario, methods, trials, seed, output, progress=None, jobs=1,
                          run=None, retry_errors=False, backend="local", ray_address=None,
                          split=None, scenario_file=None, split_seeds=None,
                          participant_condition=None, overrides=None, participant=None):
    """Runs `trials` scenes (seeds `seed`, `seed + 1`, ...) with each method, in `jobs`
    local processes or, with `backend="ray"`, as Ray tasks (on the Ray at `ray_address`,
    e.g. "HEAD:6379" or "ray://head:10001", else a new local one); writes every trial under
    `output/trials/`, then reports the folder (`report`) and returns the summary dict.
    `split` labels the seeds (`studies.splits`); `split` (for the same seeds), `scenario_file`
    and `split_seeds` None keep what the folder holds; these, `participant_condition`,
    `overrides` and `participant` (a user study's session) go into study.json
    (`write_study`).

    Trials already on disk for the same scenario are not run again (`retry_errors`: except
    those that failed with an error). A trial that raises, or whose worker process dies, is
    recorded as failed; a file that cannot be written stops the study (WriteFailed), and
    another process writing `output` refuses it (FolderLocked). `progress(done, total,
    record, elapsed)` is called after each trial; `run(scenario) -> TaskResult` replaces
    `run_task` (picklable when `jobs > 1`).
    """
    check_run_options(trials, jobs, backend, ray_address, run)
    output = pathlib.Path(output)
    # Checked before the lock too, so that a refused folder is not written at all.
    check_folder(output, scenario, scenario_hash(scenario), participant_condition)
    with study_lock(output):
        folder = prepare_folder(scenario, methods, trials, seed, output, retry_errors, split,
                                scenario_file, split_seeds, participant_condition, overrides,
                                participant)
        run_trials([folder], jobs, progress, run, backend, ray_address)
        return report(output)


@dataclasses.dataclass
class StudyFolder:
    """One method comparison's folder and the (method, trial) keys still to run."""

    scenario: object
    digest: str
    output: pathlib.Path
    seed: int
    pending: list


def check_run_options(trials, jobs, backend, ray_address, run):
    """Raises ScenarioError for a bad number of trials or jobs, backend or `run`, or a missing
    Ray, before any folder is touched."""
    if trials < 1:
        raise ScenarioError(f"trials must be at least 1, got {trials}")
    if not isinstance(jobs, int) or jobs < 1:
        raise ScenarioError(f"jobs must be a positive number of processes, got {jobs}")
    if backend not in BACKENDS:
        raise ScenarioError(f"backend must be one of {', '.join(BACKENDS)}, got {backend!r}")
    if ray_address is not None and backend != "ray":
        raise ScenarioError("ray_address needs backend='ray'")
    if backend == "ray":
        import_ray()
    if backend == "local" and jobs > 1 and run is not None:
        try:
            pickle.dumps(run)
        except Exception as error:
            raise ScenarioError(f"run={run!r} cannot be sent to worker processes ({error}): "
                                "use a module-level function, or jobs=1") from None


def prepare_folder(scenario, methods, trials, seed, output, retry_errors=False, split=None,
                   scenario_file=None, split_seeds=None, participant_condition=None,
                   overrides=None, participant=None):
    """Checks `output` again under the caller's lock (StudyFolderError for another scenario),
    removes what an interrupted study left, names the damaged trial files, writes
    study.json and returns the StudyFolder (see `run_method_comparison`)."""
    output = pathlib.Path(output)
    digest = scenario_hash(scenario)
    recorded = check_folder(output, scenario, digest, participant_condition, quiet=True)
    if split is None and recorded and (recorded.get("seed"), recorded.get("trials")) == (
            seed, trials) and isinstance(recorded.get("split"), str):
        split = recorded["split"]  # resuming the same seeds keeps their label
    if recorded:
        scenario_file = scenario_file or recorded.get("scenario_file")
        split_seeds = split_seeds or recorded.get("split_seeds")
    name_left_out(output, methods, trials, seed)
    remove_leftovers(output)  # of an interrupted study
    pending, damaged = [], []
    for method in methods:
        for trial in range(trials):
            # A damaged trial runs again; one of another scenario refuses the folder.
            before = len(damaged)
            record = read_trial(output, method, seed + trial, digest, damaged,
                                (method, trial))
            if len(damaged) > before and "another scenario" in damaged[-1].problem:
                raise StudyFolderError(f"{damaged[-1].path} is {damaged[-1].problem}: "
                                       "choose another --output folder")
            if record is None or (retry_errors and record["error"] is not None):
                pending.append((method, trial))
    name_damaged([d._replace(problem=f"{d.problem}; runs again") for d in damaged])
    write_study(output, scenario, digest, methods, trials, seed, split, scenario_file,
                split_seeds, participant_condition, overrides, participant)
    return StudyFolder(scenario, digest, output, seed, pending)


def name_left_out(output, methods, trials, seed):
    """Says on stderr which trial files in `output` a study of `methods` over `trials` seeds
    from `seed` leaves out of its summary (`trials_left_out`): their files stay, and a study
    of them all reports them together."""
    left_out = trials_left_out(output, methods, trials, seed)
    if left_out:
        print(f"pbp-drake: {output} holds trials this summary leaves out: {left_out}; their "
              f"files stay in {pathlib.Path(output) / 'trials'}, and a study of them all (its "
              "--methods, --trials and --seed) reports them together", file=sys.stderr,
              flush=True)


def run_trials(folders, jobs=1, progress=None, run=None, backend="local", ray_address=None):
    """Runs the pending trials of every StudyFolder in one pool of `jobs` local processes,
    or as Ray tasks, each trial's files into its folder. Stopped (Ctrl-C, SIGTERM, a file
    that cannot be written), it removes what the running trials left before it raises."""
    pending = [(index, method, trial) for index, folder in enumerate(folders)
               for method, trial in folder.pending]
    started = time.monotonic()
    done = []

    def on_done(key, record):
        done.append(key)
        if progress is not None:
            progress(len(done), len(pending), record, time.monotonic() - started)

    def submit_args(key):
        index, method, trial = key
        folder = folders[index]
        return (folder.scenario, method, trial, folder.seed + trial, folder.output,
                folder.digest, run)

    def on_error(key, error):
        index, method, trial = key
        folder = folders[index]
        running_marker(folder.output, method, folder.seed + trial).unlink(missing_ok=True)
        on_done(key, failed_record(folder.scenario, folder.digest, method, trial,
                                   folder.seed + trial, error, folder.output))

    try:
        if backend == "ray":
            if pending:
                run_on_ray(pending, jobs, ray_address, submit_args, on_done, on_error)
        else:
            run_locally(pending, jobs, submit_args, on_done, on_error)
    except BaseException:
        for folder in folders:
            remove_leftovers(folder.output)
        raise


def run_method_matrix(scenario, methods, pilots, trials, seed, output, progress=None, jobs=1,
                      run=None, retry_errors=False, backend="local", ray_address=None,
                      split=None, scenario_file=None, split_seeds=None, overrides=None):
    """`run_method_comparison` of every method under every pilot (`with_pilot(scenario,
    name)`), all in one pool, each pilot's trials into `output/pilots/NAME/`; then writes
    the matrix's summary, tables and figure (`report_matrix`) and returns the summary."""
    check_pilots(pilots, "pilots")
    check_run_options(trials, jobs, backend, ray_address, run)
    pilot_scenarios = {pilot: with_pilot(scenario, pilot) for pilot in pilots}
    output = pathlib.Path(output)
    digest = scenario_hash(scenario)
    recorded = check_folder(output, scenario, digest, quiet=True, kind=MATRIX)
    if recorded:
        scenario_file = scenario_file or recorded.get("scenario_file")
        split_seeds = split_seeds or recorded.get("split_seeds")
        if split is None and (recorded.get("seed"), recorded.get("trials")) == (seed, trials):
            split = recorded.get("split")
    # Every pilot's folder is checked before any is written.
    for pilot, pilot_scenario in pilot_scenarios.items():
        check_folder(pilot_folder(output, pilot), pilot_scenario, scenario_hash(pilot_scenario))
    with contextlib.ExitStack() as locks:
        for folder in [output, *(pilot_folder(output, pilot) for pilot in pilots)]:
            locks.enter_context(study_lock(folder))
        remove_leftovers(output)  # of an interrupted report
        write_matrix_study(output, scenario, digest, methods, pilots, trials, seed, split,
                           scenario_file, split_seeds, overrides)
        folders = [prepare_folder(pilot_scenario, methods, trials, seed,
                                  pilot_folder(output, pilot), retry_errors, split,
                                  scenario_file, split_seeds, overrides=overrides)
                   for pilot, pilot_scenario in pilot_scenarios.items()]
        run_trials(folders, jobs, progress, run, backend, ray_address)
        return report_matrix(output)
