"""The trials as Ray tasks (`--backend ray`), on a local Ray or a cluster
(docs/tasks/studies.md, "On Ray, here or on a cluster"). The tasks only compute; this
process writes every trial file (a cluster's nodes may not see the folder). Ray, optional
and heavy, is imported only when this backend is asked for.
"""

import contextlib
import os
import pathlib
import socket
import sys

from pbp_drake.studies.atomic_files import WriteFailed
from pbp_drake.studies.runners import compute_trial
from pbp_drake.studies.trial_files import StudyError, time_series_csv, write_trial_files

RAY_INSTALL_HINT = "pip install 'pbp_drake[ray]'"
# A Ray task whose worker process dies runs once more before it is recorded as failed.
RAY_MAX_RETRIES = 1
# This process's pbp_drake, which a cluster's workers import (see _cluster_runtime_env).
PACKAGE_DIR = pathlib.Path(__file__).resolve().parents[1]
# Seconds a `--ray-address` has to accept a connection (`check_answers`).
CONNECT_TIMEOUT = 10.0


def import_ray():
    """The `ray` module, or a StudyError that says how to install it."""
    try:
        import ray  # deferred: optional and heavy
    except ImportError as error:
        raise StudyError(f"--backend ray needs Ray, which is not installed ({error}): "
                         f"{RAY_INSTALL_HINT}") from None
    return ray


def _ray_trial(scenario, method, trial, seed, digest, run=None):
    """What a Ray task runs: the trial's record and its time series as CSV text."""
    record, result = compute_trial(scenario, method, trial, seed, digest, run)
    record["host"] = socket.gethostname()
    record["ray_node"] = import_ray().get_runtime_context().get_node_id()
    return record, None if result is None else time_series_csv(result)


def _cluster_runtime_env():
    """The cluster workers' runtime environment: this process's pbp_drake, first on their path."""
    return {"py_modules": [str(PACKAGE_DIR)], "excludes": ["__pycache__"]}


class _RaySession:
    """Ray for one study: the Ray this process runs, the cluster at `address` (left running),
    or a new local Ray of `jobs` CPUs on this process's sys.path (shut down at the end)."""

    def __init__(self, jobs, address=None):
        self.ray = import_ray()
        self.started = False
        if self.ray.is_initialized():
            return
        quiet = {"log_to_driver": False, "configure_logging": False}
        if address is not None:
            check_answers(address)
        try:
            if address is None:
                path = os.pathsep.join(p for p in sys.path if p)
                self.ray.init(address="local", num_cpus=jobs, include_dashboard=False,
                              runtime_env={"env_vars": {"PYTHONPATH": path}}, **quiet)
            else:
                self.ray.init(address=address, runtime_env=_cluster_runtime_env(), **quiet)
        except Exception as error:
            where = "start a local Ray" if address is None else f"connect to Ray at {address}"
            raise StudyError(f"could not {where}: {type(error).__name__}: {error}"
                             f"{_reason(error.__cause__)}") from None
        self.started = True

    def close(self):
        if self.started:
            self.ray.shutdown()


def check_answers(address):
    """Raises StudyError when nothing accepts a TCP connection at a `HOST:PORT` or
    `ray://HOST:PORT` address within CONNECT_TIMEOUT (Ray's own driver retries for minutes,
    silently). Other forms (`auto`) are Ray's to resolve."""
    target = address[len("ray://"):] if address.startswith("ray://") else address
    host, colon, port = target.rpartition(":")
    if not colon or not port.isdigit():
        return
    host = host.strip("[]") or "localhost"
    try:
        with socket.create_connection((host, int(port)), timeout=CONNECT_TIMEOUT):
            pass
    except OSError as error:
        reason = f"{type(error).__name__}: {error}" if str(error) else type(error).__name__
        raise StudyError(
            f"could not connect to Ray at {address}: nothing answers at {host}:{port} within "
            f"{CONNECT_TIMEOUT:g} s ({reason}); is its head node running (ray start --head)?"
        ) from None


def _reason(cause):
    """Ray's reason for a bare "Failed to connect to Ray cluster" (e.g. a missing token),
    from its cause: ` (Type: message)`, or a traceback's last line; "" without a cause."""
    if cause is None:
        return ""
    lines = [line.strip() for line in str(cause).splitlines() if line.strip()]
    if len(lines) == 1:
        return f" ({type(cause).__name__}: {lines[0]})"
    return f" ({lines[-1] if lines else type(cause).__name__})"


def _ray_error_text(ray, error):
    """A failed task's error as `Type: message`: the trial's own exception, else Ray's."""
    cause = getattr(error, "cause", None) if isinstance(
        error, ray.exceptions.RayTaskError) else None
    error = cause if isinstance(cause, BaseException) else error
    return f"{type(error).__name__}: {error}"


def run_on_ray(pending, jobs, address, submit_args, on_done, on_error):
    """Runs `pending` trial keys as Ray tasks, at most `jobs` at once, and writes each
    trial's files here, into the folder `submit_args(key)` names (`runners.run_locally`'s
    callbacks). Each distinct scenario (a matrix has one per pilot) is sent to Ray once."""
    session = _RaySession(jobs, address)
    ray = session.ray
    running = {}
    try:
        task = ray.remote(num_cpus=1, max_retries=RAY_MAX_RETRIES)(_ray_trial)
        run_ref = ray.put(submit_args(pending[0])[-1])
        scenario_refs = {}  # id(scenario) -> its object ref
        queue = list(pending)
        while queue or running:
            while queue and len(running) < jobs:
                key = queue.pop(0)
                scenario, method, trial, seed, output, digest, _ = submit_args(key)
                if id(scenario) not in scenario_refs:
                    scenario_refs[id(scenario)] = ray.put(scenario)
                ref = task.remote(scenario_refs[id(scenario)], method, trial, seed, digest,
                                  run_ref)
                running[ref] = key, output
            ready, _ = ray.wait(list(running), num_returns=1)
            for ref in ready:
                key, output = running.pop(ref)
                try:
                    record, csv_text = ray.get(ref)
                except Exception as error:  # the task failed: record it, go on
                    cause = getattr(error, "cause", None)
                    if isinstance(cause, WriteFailed):
                        raise cause from None  # the disk, not the trial: the study stops
                    on_error(key, _ray_error_text(ray, error))
                else:
                    write_trial_files(output, record, csv_text)
                    on_done(key, record)
    except BaseException:  # Ctrl-C: stop the tasks; the trials on disk are whole
        for ref in running:
            with contextlib.suppress(Exception):
                ray.cancel(ref, force=True)
        raise
    finally:
        session.close()
