"""Running trials: one trial (on disk, or computed only), and many in local processes
(`--jobs`). A trial that raises is recorded as failed with its error; one whose worker
process dies runs again alone, so that only a trial that kills its own process is recorded
as failed. A disk that fails is never a trial's result: it stops the study, as Ctrl-C does.
"""

import concurrent.futures
import dataclasses
import logging
import multiprocessing
import os
import select
import signal
import threading
import time

import numpy as np

from pbp_drake.scenarios import resolve, with_method
from pbp_drake.studies.atomic_files import (
    WriteFailed, is_disk_failure, process_alive, write_atomically, write_failed)
from pbp_drake.studies.trial_files import (
    StudyError, interaction_fields, json_float, running_marker, trial_record, write_trial)
from pbp_drake.builder.run import run_task


def run_trial(scenario, method, trial, seed, output, digest, run=None):
    """Runs one trial (what a worker process runs), writes its files and returns its record."""
    marker = running_marker(output, method, seed)
    write_atomically(marker, f"{os.getpid()}\n")
    try:
        record, result = compute_trial(scenario, method, trial, seed, digest, run)
        write_trial(output, record, result)
    finally:  # not when the process dies: then the marker tells that the trial had begun
        marker.unlink(missing_ok=True)
    return record


def compute_trial(scenario, method, trial, seed, digest, run=None):
    """Runs one trial without touching the disk: its record and TaskResult (None when it
    raised: the record holds the error). `run(resolved_scenario)` defaults to `run_task`."""
    if run is None:
        run = run_task
    started = time.monotonic()
    record = trial_record(scenario.name, digest, method, trial, seed)
    result = None
    warnings = _DrakeWarnings()
    try:
        # Resolved once: the scene is drawn and the DMPs fitted for this trial only here.
        trial = resolve(dataclasses.replace(with_method(scenario, method), seed=seed))
        record["objects"] = np.asarray(trial.scene.objects, float).tolist()
        record["targets"] = [int(t) for t in trial.scene.targets]
        result = run(trial)
        record.update(success=bool(result.success), task_time=json_float(result.task_time),
                      intervention_ratio=json_float(result.intervention_ratio),
                      switches=int(result.switches),
                      collision_ratio=json_float(result.collision_ratio),
                      peak_hand_speed=json_float(result.peak_hand_speed),
                      peak_command_acceleration=json_float(result.peak_command_acceleration),
                      ticks=len(result.times), **interaction_fields(result))
        if result.posterior_clipped_ratio is not None:  # HOP's posterior (trial_files)
            record["posterior_clipped_ratio"] = json_float(result.posterior_clipped_ratio)
        if result.angles_to_target is not None:  # the grasping task's orientation
            record.update(final_angle_to_target=json_float(result.final_angle_to_target),
                          peak_command_angular_change=json_float(
                              result.peak_command_angular_change))
    except Exception as error:  # a broken trial must not lose the study; a failing disk stops it
        if is_disk_failure(error):
            raise write_failed(error, error.filename) from error
        result = None
        record.update(success=False, error=f"{type(error).__name__}: {error}")
    finally:
        warnings.close()
    record["drake_warnings"] = warnings.count
    record["wall_time"] = round(time.monotonic() - started, 3)
    return record, result


class _DrakeWarnings(logging.Handler):
    """Counts Drake's log messages during a trial instead of printing them (differential IK
    reports every stuck step; in a study they would bury the progress bar)."""

    def __init__(self):
        super().__init__(logging.WARNING)
        self.count = 0
        self.logger = logging.getLogger("drake")
        self.saved = self.logger.propagate, list(self.logger.handlers)
        self.logger.handlers = [self]
        self.logger.propagate = False

    def emit(self, record):
        self.count += 1

    def close(self):
        self.logger.propagate, self.logger.handlers = self.saved
        super().close()


def failed_record(scenario, digest, method, trial, seed, error, output):
    """Writes and returns the record of a trial that failed outside its own code."""
    record = trial_record(scenario.name, digest, method, trial, seed)
    record["error"] = error
    write_trial(output, record)
    return record


# ---------------------------------------------------------------------------------------------
# Local processes


def trial_marker(arguments):
    """The running marker of the trial that `run_trial(*arguments)` runs."""
    scenario, method, trial, seed, output, *_ = arguments
    return running_marker(output, method, seed)


def run_locally(pending, jobs, submit_args, on_done, on_error):
    """Runs the `pending` trial keys here (`jobs == 1`) or in one pool of `jobs` processes;
    `submit_args(key)` gives `run_trial`'s arguments, `on_done(key, record)` and
    `on_error(key, text)` take each outcome."""
    if jobs == 1:
        for key in pending:
            on_done(key, run_trial(*submit_args(key)))
        return
    queue = list(pending)
    while queue:
        # A dead worker breaks the pool: the trials that had started run again, each alone;
        # those that had not go to a new pool.
        unfinished = _run_in_pool(queue, min(jobs, len(queue)), submit_args, on_done,
                                  on_error)
        started_keys = [key for key, _ in unfinished
                        if trial_marker(submit_args(key)).exists()]
        if unfinished and not started_keys:
            started_keys = [key for key, _ in unfinished]  # died before any trial began
        queue = [key for key, _ in unfinished if key not in started_keys]
        for key in started_keys:
            marker = trial_marker(submit_args(key))
            marker.unlink(missing_ok=True)
            for _, error in _run_in_pool([key], 1, submit_args, on_done, on_error):
                if not marker.exists():
                    raise StudyError(
                        f"a worker process died before it began a trial ({error}): see "
                        "the error above; a script that runs a study with jobs > 1 needs "
                        "`if __name__ == '__main__':`")
                on_error(key, error)


def _context():
    """forkserver (a clean server that has imported Drake once, each worker a fork of it),
    else spawn; never a fork of a parent whose Drake may hold threads."""
    methods = multiprocessing.get_all_start_methods()
    if "forkserver" in methods:
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(["pbp_drake.studies.runners", "pbp_drake.builder.run"])
        return context
    return multiprocessing.get_context("spawn")


def _run_in_pool(pending, jobs, submit_args, on_done, on_error):
    """Runs `pending` in a pool; returns `(key, error)` of those unfinished when a worker died."""
    with concurrent.futures.ProcessPoolExecutor(max_workers=jobs, mp_context=_context(),
                                                initializer=_start_worker,
                                                initargs=(os.getpid(),)) as pool:
        futures = {pool.submit(run_trial, *submit_args(key)): key for key in pending}
        unfinished = []
        try:
            for future in concurrent.futures.as_completed(futures):
                key = futures[future]
                try:
                    record = future.result()
                except concurrent.futures.process.BrokenProcessPool as error:
                    unfinished.append((key, f"{type(error).__name__}: {error}"))
                except WriteFailed:
                    raise  # the disk, not the trial: the study stops (below)
                except Exception as error:  # e.g. its result could not be sent back
                    on_error(key, f"{type(error).__name__}: {error}")
                else:
                    on_done(key, record)
        except BaseException:  # Ctrl-C, SIGTERM, a full disk: stop now
            processes = list((getattr(pool, "_processes", None) or {}).values())
            pool.shutdown(wait=False, cancel_futures=True)
            for process in processes:
                process.kill()
            for process in processes:
                process.join()  # none writes after this: what they left can be removed
            raise
    return unfinished


def _start_worker(study_pid):
    """Workers leave Ctrl-C to the study's process, and end when it ends, even by SIGKILL.
    Their parent is the fork server, which lives as long as a worker holds its pipe, so
    each worker watches the study's process itself."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_exit_with, args=(study_pid,), name="exit-with-study",
                     daemon=True).start()


def _exit_with(pid):
    """Kills this process when process `pid` has ended (through a pidfd, else by polling)."""
    try:
        handle = os.pidfd_open(pid)
    except ProcessLookupError:
        handle = None  # already gone
    except (AttributeError, OSError):  # no pidfd here: poll
        while process_alive(pid):
            time.sleep(0.2)
    else:
        select.select([handle], [], [])  # readable once the process has ended
    os.kill(os.getpid(), signal.SIGKILL)
