"""The files of a study folder: the trial record format, its paths, atomic writes, the
per-tick CSV time series, reading trials and studies back, and the scenario hash.

Each trial file is written atomically (a temporary file, then a rename), so an interrupted
study leaves only whole trials, and running the same study again runs only the missing ones.
"""

import csv
import dataclasses
import hashlib
import json
import math
import os
import pathlib

import numpy as np
from pydrake.common.yaml import yaml_dump_typed, yaml_load

from pbp_drake.scenarios import ScenarioError
from pbp_drake.builder.run import TaskResult

# A trial file of another format counts as not on disk (it runs again). Fields added since
# (peak_hand_speed, peak_command_acceleration) are read as None when a file lacks them, so
# they did not change the format: older trials still count and report them as n/a.
TRIAL_FORMAT = 1
# The metrics of a trial, in the order of the trial files and of trials.json. The peaks are
# TaskResult's (see pbp_drake.builder.run.motion_peaks): peak_hand_speed (m/s), the largest
# one-tick hand speed, max_k |ee(t_{k+1}) - ee(t_k)| / control_period, and
# peak_command_acceleration (m/s^2), max_k |v_cmd(k+1) - v_cmd(k)| / control_period, over
# the CSV's ee_x..ee_z and command_vx..command_vz columns (ticks 0..T-1).
METRICS = ("success", "task_time", "intervention_ratio", "switches", "collision_ratio",
           "peak_hand_speed", "peak_command_acceleration")
TRIAL_FIELDS = ("method", "trial", "seed", *METRICS, "error")


class StudyError(ScenarioError):
    """The study cannot run or be reported (not a trial's failure: those are recorded)."""


class StudyFolderError(StudyError):
    """The output folder holds a different study, or no study at all."""


# ---------------------------------------------------------------------------------------------
# The scenario's identity


def plain(value):
    """A dataclass tree as JSON-able data that keeps each dataclass's type name (two operator
    configs with the same fields are different scenarios). Drake's config structs
    (`SimulatorConfig`, `MultibodyPlantConfig`) become their YAML fields."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {"!type": type(value).__name__,
                **{f.name: plain(getattr(value, f.name)) for f in dataclasses.fields(value)}}
    if hasattr(type(value), "__fields__"):  # a Drake struct bound with its field list
        return {"!type": type(value).__name__, **yaml_load(data=yaml_dump_typed(value))}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    return value


def scenario_content(scenario):
    """Everything in the scenario but its method and seed (a study sets those per trial),
    as plain data."""
    return plain(dataclasses.replace(scenario, method="", seed=0))


def scenario_hash(scenario):
    """A short hash of `scenario_content`: trials of different scenarios are never mixed in
    one folder."""
    content = scenario_content(scenario)
    text = json.dumps(content, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


# ---------------------------------------------------------------------------------------------
# Writing


def trial_paths(output, method, seed):
    """The JSON and CSV files of one trial."""
    folder = pathlib.Path(output) / "trials" / method
    return folder / f"seed_{seed}.json", folder / f"seed_{seed}.csv"


def running_marker(output, method, seed):
    """Present while a process runs the trial: after a worker dies, it tells the trials
    that had started from those that had not."""
    return trial_paths(output, method, seed)[0].with_suffix(".running")


def write_atomically(path, text):
    """Writes `text` to a temporary file beside `path`, then renames it to `path`."""
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with open(temporary, "w", newline="") as stream:
        stream.write(text)
        stream.flush()
        os.fsync(stream.fileno())
    os.replace(temporary, path)


def json_float(value):
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


def trial_record(scenario_name, digest, method, trial, seed):
    """A trial's record before it runs: not successful, no metrics, no error."""
    return {"format": TRIAL_FORMAT, "scenario": scenario_name, "scenario_hash": digest,
            "method": method, "trial": trial, "seed": seed, "success": False,
            "task_time": None, "intervention_ratio": None, "switches": None,
            "collision_ratio": None, "peak_hand_speed": None,
            "peak_command_acceleration": None, "ticks": 0, "objects": None, "targets": None,
            "time_series": None, "error": None, "drake_warnings": 0, "wall_time": None}


def write_trial(output, record, result=None):
    """Writes a trial's CSV (when it ran) and then its JSON: the JSON marks it done."""
    write_trial_files(output, record, None if result is None else time_series_csv(result))


def write_trial_files(output, record, csv_text):
    """write_trial with the time series already as CSV text (None: the trial did not run)."""
    json_path, csv_path = trial_paths(output, record["method"], record["seed"])
    if csv_text is not None:
        write_atomically(csv_path, csv_text)
        record["time_series"] = csv_path.name
    write_atomically(json_path, json.dumps(record, indent=1) + "\n")


def write_study(output, scenario, digest, methods, trials, seed):
    """Writes the folder's study.json: which scenario, methods, trials and seeds."""
    study = {"study": "method_comparison", "format": TRIAL_FORMAT, "scenario": scenario.name,
             "scenario_hash": digest, "methods": list(methods), "trials": trials, "seed": seed,
             "scenario_content": scenario_content(scenario)}
    write_atomically(output / "study.json", json.dumps(study, indent=2) + "\n")


def check_folder(output, scenario, digest):
    """Raises StudyFolderError when `output` holds a study of another scenario."""
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


# ---------------------------------------------------------------------------------------------
# Reading


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
        collision_ratio=record["collision_ratio"], in_collision=in_collision,
        peak_hand_speed=record.get("peak_hand_speed"),
        peak_command_acceleration=record.get("peak_command_acceleration"))


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
