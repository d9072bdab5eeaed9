"""Comparing methods on the same seeded HSR scenes: `pbp-drake study diagrams/hsr_reach.yaml`.

A study folder `DIR` holds everything needed to rebuild its tables and figures:

    DIR/study.json                        the study: scenario name and hash, methods, trials, seed
    DIR/trials/<method>/seed_<seed>.json  one trial: its metrics, scene, error (the marker that
                                          the trial is done)
    DIR/trials/<method>/seed_<seed>.csv   its time series, one row per control tick
    DIR/summary.json, DIR/results.md, DIR/trials.json, DIR/fig7*.png
                                          rebuilt from the files above by `report`

Trial i of every method uses seed `seed + i`: the same scene and participant noise. Each trial
file is written atomically (a temporary file, then a rename), so an interrupted study leaves
only whole trials, and running the same study again runs only the missing ones.

Trials run in local processes (`--jobs`), or as Ray tasks (`--backend ray`, on a local Ray
or a cluster): then the tasks only compute, and this process writes every trial file, so
the folder is the same as with local processes.
"""

import concurrent.futures
import csv
import dataclasses
import hashlib
import json
import logging
import math
import multiprocessing
import os
import pathlib
import pickle
import signal
import sys
import time

import numpy as np

from pbp_drake.scenarios import ScenarioError, parse_method_label, with_method

TRIAL_FORMAT = 1
# Collision-ratio histogram: 20 bins of 0.05 over [0, 1] (the last bin includes 1).
HISTOGRAM_EDGES = tuple(round(0.05 * i, 2) for i in range(21))
# The metrics of a trial, in the order of the trial files and of trials.json.
METRICS = ("success", "task_time", "intervention_ratio", "switches", "collision_ratio")
TRIAL_FIELDS = ("method", "trial", "seed", *METRICS, "error")
SIGNIFICANT_DIGITS = 12


class StudyError(ScenarioError):
    """The study cannot run or be reported (not a trial's failure: those are recorded)."""


class StudyFolderError(StudyError):
    """The output folder holds a different study, or no study at all."""


# ---------------------------------------------------------------------------------------------
# The scenario's identity


def _plain(value):
    """A dataclass tree as JSON-able data that keeps each dataclass's type name (two operator
    configs with the same fields are different scenarios)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {"!type": type(value).__name__,
                **{f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    return value


def scenario_hash(scenario):
    """A short hash of everything in the scenario but its method and seed (a study sets
    those per trial): trials of different scenarios are never mixed in one folder."""
    content = _plain(dataclasses.replace(scenario, method="", seed=0))
    text = json.dumps(content, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


# ---------------------------------------------------------------------------------------------
# Files


def trial_paths(output, method, seed):
    """The JSON and CSV files of one trial."""
    folder = pathlib.Path(output) / "trials" / method
    return folder / f"seed_{seed}.json", folder / f"seed_{seed}.csv"


def _write_atomically(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with open(temporary, "w", newline="") as stream:
        stream.write(text)
        stream.flush()
        os.fsync(stream.fileno())
    os.replace(temporary, path)


def _float(value):
    """A float for JSON: None for NaN and infinities (JSON has no NaN)."""
    if value is None:
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def time_series_columns(has_collision):
    return ["time", "ee_x", "ee_y", "ee_z", "heading",
            "command_x", "command_y", "command_z", "command_vx", "command_vy", "command_vz",
            "command_heading", "operator_active",
            "operator_vx", "operator_vy", "operator_vz", "operator_yaw_rate",
            "selected_goal", "target"] + (["in_collision"] if has_collision else [])


def time_series_csv(result):
    """The per-tick time series of a TaskResult as CSV text; floats are written in their
    shortest exact form, so reading them back gives the same numbers."""
    has_collision = result.in_collision is not None
    columns = time_series_columns(has_collision)
    lines = [",".join(columns)]
    for k in range(len(result.times)):
        row = [result.times[k], *result.ee_positions[k], result.headings[k], *result.commands[k]]
        row = [repr(float(x)) for x in row]
        row.append(str(int(bool(result.operator_active[k]))))
        row += [repr(float(x)) for x in result.operator_commands[k]]
        row += [str(int(result.selected_goals[k])), str(int(result.targets[k]))]
        if has_collision:
            row.append(str(int(bool(result.in_collision[k]))))
        lines.append(",".join(row))
    return "\n".join(lines) + "\n"


def read_time_series(path):
    """A trial's CSV as a dict of arrays keyed by column name."""
    with open(path, newline="") as stream:
        reader = csv.reader(stream)
        columns = next(reader)
        rows = list(reader)
    integers = {"operator_active", "selected_goal", "target", "in_collision"}
    data = {}
    for index, name in enumerate(columns):
        values = [row[index] for row in rows]
        data[name] = (np.array(values, dtype=int) if name in integers
                      else np.array(values, dtype=float))
    return data


def load_task_result(output, method, seed):
    """The TaskResult of a finished trial, read back from its JSON and CSV files."""
    from pbp_drake.task_run import TaskResult

    json_path, csv_path = trial_paths(output, method, seed)
    record = json.loads(json_path.read_text())
    if record["error"] is not None:
        raise ValueError(f"{json_path}: the trial failed: {record['error']}")
    series = read_time_series(csv_path)
    in_collision = series["in_collision"].astype(bool) if "in_collision" in series else None
    return TaskResult(
        success=record["success"], task_time=record["task_time"],
        intervention_ratio=record["intervention_ratio"], switches=record["switches"],
        times=series["time"],
        ee_positions=np.column_stack([series["ee_x"], series["ee_y"], series["ee_z"]]),
        headings=series["heading"],
        commands=np.column_stack([series[c] for c in (
            "command_x", "command_y", "command_z", "command_vx", "command_vy", "command_vz",
            "command_heading")]),
        operator_active=series["operator_active"].astype(bool),
        operator_commands=np.column_stack([series[c] for c in (
            "operator_vx", "operator_vy", "operator_vz", "operator_yaw_rate")]),
        selected_goals=series["selected_goal"], targets=series["target"],
        objects=np.array(record["objects"], float),
        collision_ratio=record["collision_ratio"], in_collision=in_collision)


def _trial_record(scenario_name, digest, method, trial, seed):
    return {"format": TRIAL_FORMAT, "scenario": scenario_name, "scenario_hash": digest,
            "method": method, "trial": trial, "seed": seed, "success": False,
            "task_time": None, "intervention_ratio": None, "switches": None,
            "collision_ratio": None, "ticks": 0, "objects": None, "targets": None,
            "time_series": None, "error": None, "drake_warnings": 0, "wall_time": None}


def write_trial(output, record, result=None):
    """Writes a trial's CSV (when it ran) and then its JSON: the JSON marks it done."""
    _write_trial_files(output, record, None if result is None else time_series_csv(result))


def _write_trial_files(output, record, csv_text):
    """write_trial with the time series already as CSV text (None: the trial did not run)."""
    json_path, csv_path = trial_paths(output, record["method"], record["seed"])
    if csv_text is not None:
        _write_atomically(csv_path, csv_text)
        record["time_series"] = csv_path.name
    _write_atomically(json_path, json.dumps(record, indent=1) + "\n")


def read_trial(output, method, seed, digest=None):
    """A trial's JSON record if it is on disk and whole, else None. Raises StudyFolderError
    when it belongs to another scenario than `digest`."""
    json_path, csv_path = trial_paths(output, method, seed)
    try:
        record = json.loads(json_path.read_text())
    except (OSError, ValueError):
        return None
    if (not isinstance(record, dict) or record.get("format") != TRIAL_FORMAT
            or record.get("method") != method or record.get("seed") != seed):
        return None
    if digest is not None and record.get("scenario_hash") != digest:
        raise StudyFolderError(
            f"{json_path} is a trial of another scenario ({record.get('scenario')!r}, hash "
            f"{record.get('scenario_hash')}, not {digest}): choose another --output folder")
    if record["error"] is None and not csv_path.is_file():
        return None
    return record


# ---------------------------------------------------------------------------------------------
# Running trials


def _scene_of(scenario):
    from pbp_drake.scenarios import task_layout

    layout = task_layout(scenario)
    return (np.asarray(layout.objects, float).tolist(), [int(t) for t in layout.targets])


def run_trial(scenario, method, trial, seed, output, digest, run=None):
    """Runs one trial and writes its files; a trial that raises is written as failed with
    its error. Returns its record. This is what a worker process runs."""
    marker = _running_marker(output, method, seed)
    marker.parent.mkdir(parents=True, exist_ok=True)
    marker.write_text(f"{os.getpid()}\n")
    record, result = compute_trial(scenario, method, trial, seed, digest, run)
    write_trial(output, record, result)
    marker.unlink(missing_ok=True)
    return record


def compute_trial(scenario, method, trial, seed, digest, run=None):
    """Runs one trial without touching the disk: its record and TaskResult (None when it
    raised: the record then holds the error)."""
    if run is None:
        from pbp_drake.task_run import run_task as run
    started = time.monotonic()
    record = _trial_record(scenario.name, digest, method, trial, seed)
    result = None
    warnings = _DrakeWarnings()
    try:
        trial_scenario = dataclasses.replace(with_method(scenario, method), seed=seed)
        record["objects"], record["targets"] = _scene_of(trial_scenario)
        result = run(trial_scenario)
        record.update(success=bool(result.success), task_time=_float(result.task_time),
                      intervention_ratio=_float(result.intervention_ratio),
                      switches=int(result.switches),
                      collision_ratio=_float(result.collision_ratio),
                      ticks=len(result.times))
    except Exception as error:  # a broken trial must not lose the study
        result = None
        record.update(success=False, error=f"{type(error).__name__}: {error}")
    finally:
        warnings.close()
    record["drake_warnings"] = warnings.count
    record["wall_time"] = round(time.monotonic() - started, 3)
    return record, result


def _ray_trial(scenario, method, trial, seed, digest, run=None):
    """What a Ray task runs: the trial's record and its time series as CSV text (the
    process that runs the study writes the files: a cluster's nodes may not see them)."""
    record, result = compute_trial(scenario, method, trial, seed, digest, run)
    return record, None if result is None else time_series_csv(result)


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


def _running_marker(output, method, seed):
    """Present while a process runs the trial: after a worker dies, it tells the trials
    that had started from those that had not."""
    return trial_paths(output, method, seed)[0].with_suffix(".running")


def _failed_record(scenario, digest, method, trial, seed, error, output):
    record = _trial_record(scenario.name, digest, method, trial, seed)
    record["error"] = error
    write_trial(output, record)
    return record


def _context():
    """forkserver (a clean server that has imported Drake once, each worker a fork of it),
    else spawn; never a fork of a parent whose Drake may hold threads."""
    methods = multiprocessing.get_all_start_methods()
    if "forkserver" in methods:
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(["pbp_drake.method_study", "pbp_drake.task_run"])
        return context
    return multiprocessing.get_context("spawn")


def _run_in_pool(pending, jobs, submit_args, on_done, on_error):
    """Runs `pending` trial keys in a pool of `jobs` processes. Returns the keys that were
    unfinished when a worker process died (the pool is then broken), with the error."""
    with concurrent.futures.ProcessPoolExecutor(max_workers=jobs, mp_context=_context(),
                                                initializer=_ignore_interrupts) as pool:
        futures = {pool.submit(run_trial, *submit_args(key)): key for key in pending}
        unfinished = []
        try:
            for future in concurrent.futures.as_completed(futures):
                key = futures[future]
                try:
                    record = future.result()
                except concurrent.futures.process.BrokenProcessPool as error:
                    unfinished.append((key, f"{type(error).__name__}: {error}"))
                except Exception as error:  # e.g. the worker could not write the files
                    on_error(key, f"{type(error).__name__}: {error}")
                else:
                    on_done(key, record)
        except BaseException:  # Ctrl-C: stop now; the trials on disk are whole
            processes = list((getattr(pool, "_processes", None) or {}).values())
            pool.shutdown(wait=False, cancel_futures=True)
            for process in processes:
                process.terminate()
            raise
    return unfinished


def _ignore_interrupts():
    """Workers leave Ctrl-C to the study's process, which stops them."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


BACKENDS = ("local", "ray")
RAY_INSTALL_HINT = "pip install 'pbp_drake[ray]'"
# A Ray task whose worker process dies runs once more (as a local worker's trial runs again
# alone) before it is recorded as failed; a trial that raises is recorded at once.
RAY_MAX_RETRIES = 1


def _import_ray():
    try:
        import ray
    except ImportError as error:
        raise StudyError(f"--backend ray needs Ray, which is not installed ({error}): "
                         f"{RAY_INSTALL_HINT}") from None
    return ray


class _RaySession:
    """Ray for one study: with no address, a new local Ray of `jobs` CPUs, whose workers
    see this process's sys.path (as local worker processes do), shut down at the end; with
    an address, that cluster (left running). A Ray this process already runs is used as is."""

    def __init__(self, jobs, address=None):
        self.ray = _import_ray()
        self.started = False
        if self.ray.is_initialized():
            return
        quiet = {"log_to_driver": False, "configure_logging": False}
        try:
            if address is None:
                path = os.pathsep.join(p for p in sys.path if p)
                self.ray.init(address="local", num_cpus=jobs, include_dashboard=False,
                              runtime_env={"env_vars": {"PYTHONPATH": path}}, **quiet)
            else:
                self.ray.init(address=address, **quiet)
        except Exception as error:
            where = "start a local Ray" if address is None else f"connect to Ray at {address}"
            raise StudyError(f"could not {where}: {type(error).__name__}: {error}") from None
        self.started = True

    def close(self):
        if self.started:
            self.started = False
            self.ray.shutdown()


def _ray_error_text(ray, error):
    """A failed task's error as `Type: message`: a trial's own exception when it has one
    (as the local backend records it), else Ray's (e.g. WorkerCrashedError)."""
    cause = getattr(error, "cause", None) if isinstance(
        error, ray.exceptions.RayTaskError) else None
    error = cause if isinstance(cause, BaseException) else error
    return f"{type(error).__name__}: {error}"


def _run_on_ray(pending, jobs, address, submit_args, output, on_done, on_error):
    """Runs `pending` trial keys as Ray tasks, at most `jobs` at once, and writes each
    trial's files here as its task finishes; a task that fails is recorded as failed."""
    session = _RaySession(jobs, address)
    ray = session.ray
    running = {}
    try:
        task = ray.remote(num_cpus=1, max_retries=RAY_MAX_RETRIES)(_ray_trial)
        scenario, *_, digest, run = submit_args(pending[0])
        scenario_ref, run_ref = ray.put(scenario), ray.put(run)
        queue = list(pending)
        while queue or running:
            while queue and len(running) < jobs:
                key = queue.pop(0)
                _, method, trial, seed, *_ = submit_args(key)
                running[task.remote(scenario_ref, method, trial, seed, digest, run_ref)] = key
            ready, _ = ray.wait(list(running), num_returns=1)
            for ref in ready:
                key = running.pop(ref)
                try:
                    record, csv_text = ray.get(ref)
                except Exception as error:  # the task failed: record it, go on
                    on_error(key, _ray_error_text(ray, error))
                else:
                    _write_trial_files(output, record, csv_text)
                    on_done(key, record)
    except BaseException:  # Ctrl-C: stop the tasks; the trials on disk are whole
        for ref in running:
            try:
                ray.cancel(ref, force=True)
            except Exception:
                pass
        raise
    finally:
        session.close()


def run_method_comparison(scenario, methods, trials, seed, output, progress=None, jobs=1,
                          run=None, retry_errors=False, backend="local", ray_address=None):
    """Runs `trials` scenes (seeds `seed`, `seed + 1`, ...) with each method, in `jobs`
    processes, writes every trial under `output/trials/`, then the summary, tables and
    figures (see `report`). Returns the summary dict.

    `backend="ray"` runs the trials as Ray tasks, at most `jobs` at once: on a new local
    Ray of `jobs` CPUs, or on the Ray at `ray_address` (e.g. "ray://head:10001", "auto"),
    whose workers must be able to import pbp_drake. This process writes the trial files,
    the same as with local processes, so the summary is the same bytes.

    Trials already on disk for the same scenario are not run again (`retry_errors`: except
    those that failed with an error). A trial that raises, or whose worker process dies, is
    recorded as failed with its error. `progress(done, total, record, elapsed)` is called
    after each trial run now. `run(scenario) -> TaskResult` replaces `run_task` (it must be
    picklable when `jobs > 1`).
    """
    if not isinstance(jobs, int) or jobs < 1:
        raise ScenarioError(f"jobs must be a positive number of processes, got {jobs}")
    if backend not in BACKENDS:
        raise ScenarioError(f"backend must be one of {', '.join(BACKENDS)}, got {backend!r}")
    if ray_address is not None and backend != "ray":
        raise ScenarioError("ray_address needs backend='ray'")
    if trials < 1:
        raise ScenarioError(f"trials must be at least 1, got {trials}")
    output = pathlib.Path(output)
    digest = scenario_hash(scenario)
    _check_folder(output, scenario, digest)
    keys = [(method, trial) for method in methods for trial in range(trials)]
    for leftover in [*output.glob("trials/*/*.running"), *output.glob("trials/*/.*.tmp")]:
        leftover.unlink(missing_ok=True)  # left by an interrupted study
    if backend == "ray":
        _import_ray()  # fail before touching the folder when Ray is missing
    if backend == "local" and jobs > 1 and run is not None:
        try:
            pickle.dumps(run)
        except Exception as error:
            raise ScenarioError(f"run={run!r} cannot be sent to worker processes ({error}): "
                                "use a module-level function, or jobs=1") from None
    pending = []
    for method, trial in keys:
        record = read_trial(output, method, seed + trial, digest)
        if record is None or (retry_errors and record["error"] is not None):
            pending.append((method, trial))
    _write_study(output, scenario, digest, methods, trials, seed)

    started = time.monotonic()
    done = []

    def on_done(key, record):
        done.append(key)
        if progress is not None:
            progress(len(done), len(pending), record, time.monotonic() - started)

    def submit_args(key):
        method, trial = key
        return (scenario, method, trial, seed + trial, output, digest, run)

    def on_error(key, error):
        method, trial = key
        _running_marker(output, method, seed + trial).unlink(missing_ok=True)
        on_done(key, _failed_record(scenario, digest, method, trial, seed + trial, error,
                                    output))

    if backend == "ray":
        if pending:
            _run_on_ray(pending, jobs, ray_address, submit_args, output, on_done, on_error)
    elif jobs == 1:
        for key in pending:
            on_done(key, run_trial(*submit_args(key)))
    else:
        queue = list(pending)
        while queue:
            # A dead worker breaks the pool. The trials that had started run again, each
            # alone, so that only one that kills its own process is recorded as failed; those
            # that had not started go to a new pool.
            unfinished = _run_in_pool(queue, min(jobs, len(queue)), submit_args, on_done,
                                      on_error)
            started_keys = [key for key, _ in unfinished
                            if _running_marker(output, key[0], seed + key[1]).exists()]
            if unfinished and not started_keys:
                started_keys = [key for key, _ in unfinished]  # died before any trial began
            queue = [key for key, _ in unfinished if key not in started_keys]
            for key in started_keys:
                marker = _running_marker(output, key[0], seed + key[1])
                marker.unlink(missing_ok=True)
                for _, error in _run_in_pool([key], 1, submit_args, on_done, on_error):
                    if not marker.exists():
                        raise StudyError(
                            f"a worker process died before it began a trial ({error}): see "
                            "the error above; a script that runs a study with jobs > 1 needs "
                            "`if __name__ == '__main__':`")
                    on_error(key, error)
    return report(output)


def _check_folder(output, scenario, digest):
    study_path = output / "study.json"
    if not study_path.is_file():
        return
    try:
        study = json.loads(study_path.read_text())
    except ValueError:
        return
    if study.get("scenario_hash") != digest:
        raise StudyFolderError(
            f"{output} holds a study of another scenario ({study.get('scenario')!r}, hash "
            f"{study.get('scenario_hash')}; this one is {scenario.name!r}, hash {digest}): "
            "choose another --output folder")


def _write_study(output, scenario, digest, methods, trials, seed):
    study = {"study": "method_comparison", "format": TRIAL_FORMAT, "scenario": scenario.name,
             "scenario_hash": digest, "methods": list(methods), "trials": trials, "seed": seed,
             "scenario_content": _plain(dataclasses.replace(scenario, method="", seed=0))}
    _write_atomically(output / "study.json", json.dumps(study, indent=2) + "\n")


# ---------------------------------------------------------------------------------------------
# The summary, tables and figures, from the files only


def _round(value):
    if value is None or not math.isfinite(value):
        return None
    return float(f"{value:.{SIGNIFICANT_DIGITS}g}")


def _mean_std(values):
    values = [v for v in values if v is not None and math.isfinite(v)]
    if not values:
        return {"mean": None, "std": None}
    mean = math.fsum(values) / len(values)
    variance = math.fsum((v - mean) ** 2 for v in values) / len(values)
    return {"mean": _round(mean), "std": _round(math.sqrt(variance))}


def collision_histogram(ratios):
    """Counts of collision ratios in the bins of HISTOGRAM_EDGES (the last includes 1)."""
    counts = [0] * (len(HISTOGRAM_EDGES) - 1)
    for ratio in ratios:
        index = int(np.searchsorted(HISTOGRAM_EDGES, ratio, side="right")) - 1
        counts[min(max(index, 0), len(counts) - 1)] += 1
    return counts


def read_study(output):
    """The study.json of a study folder and its trials' records, in method then seed order
    (None for a trial not on disk)."""
    output = pathlib.Path(output)
    study_path = output / "study.json"
    try:
        study = json.loads(study_path.read_text())
    except OSError:
        raise StudyFolderError(f"{output} has no study.json: is it the --output folder of a "
                               "`pbp-drake study`?") from None
    except ValueError as error:
        raise StudyFolderError(f"{study_path} is not valid JSON: {error}") from None
    records = {}
    for method in study["methods"]:
        for trial in range(study["trials"]):
            records[(method, trial)] = read_trial(output, method, study["seed"] + trial,
                                                  study["scenario_hash"])
    return study, records


def summarize(study, records):
    """Per method: how many trials, errors and missing; success rate over the trials on
    disk; mean and (population) std of intervention ratio and task time, and the mean, std
    and histogram of the collision ratio, over the trials that ran without error. Only
    values from the trial files, in a fixed order, rounded: byte-identical for any --jobs."""
    summary = {"study": "method_comparison", "scenario": study["scenario"],
               "scenario_hash": study["scenario_hash"], "trials": study["trials"],
               "seed": study["seed"], "collision_histogram_edges": list(HISTOGRAM_EDGES),
               "methods": {}}
    for method in study["methods"]:
        rows = [records[(method, trial)] for trial in range(study["trials"])]
        present = [r for r in rows if r is not None]
        ran = [r for r in present if r["error"] is None]
        ratios = [r["collision_ratio"] for r in ran if r["collision_ratio"] is not None]
        collision = _mean_std(ratios)
        collision["histogram"] = collision_histogram(ratios)
        summary["methods"][method] = {
            "trials": len(present),
            "missing": len(rows) - len(present),
            "errors": len(present) - len(ran),
            "error_seeds": [r["seed"] for r in present if r["error"] is not None],
            "success_rate": _round(sum(bool(r["success"]) for r in present) / len(present))
            if present else None,
            "intervention_ratio": _mean_std([r["intervention_ratio"] for r in ran]),
            "task_time": _mean_std([r["task_time"] for r in ran]),
            "collision_ratio": collision,
            "collision_free_trials": sum(ratio == 0.0 for ratio in ratios) if ratios else None,
        }
    arbitration = ideal_alpha(summary["methods"])
    if arbitration is not None:
        summary["arbitration"] = arbitration
    return summary


# The paper's ideal arbitration (section IV-A) is the highest alpha that still lets the
# operator do the task, since a lower one takes autonomy from the robot for nothing. Doing
# the task here: this success rate, and where collisions are measured, most trials without
# any (the bar PBP has to meet in the obstacle task).
IDEAL_ALPHA_SUCCESS = 0.95


def ideal_alpha(methods):
    """`{"alphas": [...], "ideal_alpha": A or None, "criterion": text}` over the study's
    `fixed_alpha=A` methods (None when it has none)."""
    swept = []
    for label, entry in methods.items():
        name, alpha = parse_method_label(label)
        if name == "fixed_alpha" and alpha is not None:
            swept.append((alpha, entry))
    if not swept:
        return None
    good = []
    for alpha, entry in swept:
        ran = entry["trials"] - entry["errors"]
        does_task = (entry["success_rate"] is not None
                     and entry["success_rate"] >= IDEAL_ALPHA_SUCCESS)
        if entry["collision_free_trials"] is not None:
            does_task = does_task and 2 * entry["collision_free_trials"] > ran
        if does_task:
            good.append(alpha)
    return {"alphas": sorted(alpha for alpha, _ in swept),
            "ideal_alpha": max(good) if good else None,
            "criterion": f"highest alpha with success >= {IDEAL_ALPHA_SUCCESS:.0%} and, "
                         "where collisions are measured, most trials free of them"}


def _cell(entry, field, digits):
    value = entry[field]
    if value["mean"] is None:
        return "-"
    return f"{value['mean']:.{digits}f} ± {value['std']:.{digits}f}"


def results_table(summary):
    """The summary as a Markdown table, one row per method."""
    from pbp_drake.study_figures import METHOD_LABELS

    lines = ["| method | trials | success | intervention ratio | task time (s) | "
             "collision ratio | collision-free trials | errors |",
             "|---|---|---|---|---|---|---|---|"]
    for method, entry in summary["methods"].items():
        rate = "-" if entry["success_rate"] is None else f"{100 * entry['success_rate']:.0f} %"
        trials = f"{entry['trials']}" + (f" ({entry['missing']} missing)"
                                         if entry["missing"] else "")
        lines.append(f"| {METHOD_LABELS.get(method, method)} | {trials} | {rate} | "
                     f"{_cell(entry, 'intervention_ratio', 3)} | "
                     f"{_cell(entry, 'task_time', 1)} | {_cell(entry, 'collision_ratio', 3)} | "
                     f"{_count(entry['collision_free_trials'])} | {entry['errors']} |")
    arbitration = summary.get("arbitration")
    if arbitration is not None:
        ideal = arbitration["ideal_alpha"]
        lines += ["", f"Ideal fixed alpha: {'none' if ideal is None else ideal} "
                      f"({arbitration['criterion']})."]
    return "\n".join(lines) + "\n"


def _count(value):
    return "-" if value is None else str(value)


def _flat_trials(study, records):
    rows = []
    for method in study["methods"]:
        for trial in range(study["trials"]):
            record = records[(method, trial)]
            if record is not None:
                rows.append({field: record[field] for field in TRIAL_FIELDS})
    return rows


FIGURES = ("fig7a_intervention.png", "fig7b_task_time.png", "fig7c_collisions.png")


def report(output):
    """Rebuilds `summary.json`, `results.md`, `trials.json` and the figures of a study folder
    from its study.json and trial files only (no simulation). Returns the summary."""
    from pbp_drake.study_figures import (
        plot_collision_histogram, plot_intervention, plot_task_time)

    output = pathlib.Path(output)
    study, records = read_study(output)
    summary = summarize(study, records)
    _write_atomically(output / "summary.json", json.dumps(summary, indent=2) + "\n")
    _write_atomically(output / "results.md", results_table(summary))
    _write_atomically(output / "trials.json",
                      json.dumps(_flat_trials(study, records), indent=1) + "\n")
    rows = [r for r in records.values() if r is not None]
    methods = study["methods"]
    plot_intervention(rows, methods, output / FIGURES[0])
    plot_task_time(rows, methods, output / FIGURES[1])
    plot_collision_histogram(summary, output / FIGURES[2])
    return summary


# ---------------------------------------------------------------------------------------------
# A text progress bar


class ProgressBar:
    """`progress(done, total, record, elapsed)` as one line on `stream`: rewritten in place
    on a terminal, else printed every `every` trials (default: about 20 lines a study)."""

    def __init__(self, stream=None, width=30, every=None):
        self.stream = sys.stderr if stream is None else stream
        self.width = width
        self.every = every
        self.failures = 0
        self.errors = 0
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def line(self, done, total, elapsed):
        filled = int(round(self.width * done / total)) if total else self.width
        eta = elapsed / done * (total - done) if done else float("nan")
        eta_text = _duration(eta) if math.isfinite(eta) else "?"
        return (f"[{'#' * filled}{'.' * (self.width - filled)}] {done}/{total} trials, "
                f"{self.failures} failed ({self.errors} errors), {_duration(elapsed)} elapsed,"
                f" ETA {eta_text}")

    def __call__(self, done, total, record, elapsed):
        if not record["success"]:
            self.failures += 1
        if record["error"] is not None:
            self.errors += 1
        text = self.line(done, total, elapsed)
        if self.tty:
            self.stream.write("\r" + text + ("\n" if done == total else ""))
        else:
            every = self.every or max(1, total // 20)
            if done % every == 0 or done == total or record["error"] is not None:
                suffix = (f"  ({record['method']} seed {record['seed']}: {record['error']})"
                          if record["error"] is not None else "")
                self.stream.write(text + suffix + "\n")
        self.stream.flush()


def _duration(seconds):
    seconds = int(round(seconds))
    if seconds >= 3600:
        return f"{seconds // 3600}h{seconds % 3600 // 60:02d}m"
    if seconds >= 60:
        return f"{seconds // 60}m{seconds % 60:02d}s"
    return f"{seconds}s"
