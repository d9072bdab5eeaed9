"""The files of a study folder: the trial record format, its paths, the per-tick CSV time
series, reading trials and studies back, and the scenario hash. Each file is written
atomically (`studies.atomic_files`), so a study that stops leaves only whole trials.
"""

import collections
import csv
import dataclasses
import hashlib
import json
import math
import pathlib
import sys

import numpy as np
from pydrake.common.yaml import yaml_dump_typed, yaml_load

from pbp_drake.core.intent_filter import IntentFilterSettings
from pbp_drake.scenarios import ScenarioError, counted
from pbp_drake.scenarios.bounds import is_special_file
from pbp_drake.studies.atomic_files import (
    MOST_READ_BYTES, read_json, read_text, write_atomically)
from pbp_drake.builder.run import TaskResult
from pbp_drake.builder.time_series import (
    HAND_ORIENTATION_COLUMNS, time_series_columns, time_series_csv)

# The kind (study.json's "study") of a `pbp-drake study` or a session's folder.
METHOD_COMPARISON = "method_comparison"

# A trial file of another format counts as not on disk (it runs again); a metric a file
# lacks reads as None (reported n/a), so a new metric does not change the format.
TRIAL_FORMAT = 1
# The metrics of a trial, in the order of the trial files and of trials.json (the interaction
# metrics: `pbp_drake.core.interaction_metrics`).
INTERACTION_METRICS = ("input_integral", "turn_input_integral", "idle_ratio", "agreement",
                       "prediction_accuracy", "time_to_prediction", "mean_time_to_prediction",
                       "unpredicted_switches")
METRICS = ("success", "task_time", "intervention_ratio", "switches", "collision_ratio",
           "peak_hand_speed", "peak_command_acceleration", "posterior_clipped_ratio",
           *INTERACTION_METRICS)
TRIAL_FIELDS = ("method", "trial", "seed", *METRICS, "error")


class StudyError(ScenarioError):
    """The study cannot run or be reported (not a trial's failure: those are recorded)."""


class StudyFolderError(StudyError):
    """The output folder holds a different study, or no study at all."""


# ---------------------------------------------------------------------------------------------
# The scenario's identity


def plain(value):
    """A dataclass tree as JSON-able data that keeps each dataclass's type name (two operator
    configs with the same fields are different scenarios); Drake's config structs become
    their YAML fields."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {"!type": type(value).__name__,
                **{f.name: plain(getattr(value, f.name)) for f in dataclasses.fields(value)}}
    if hasattr(type(value), "__fields__"):  # a Drake struct bound with its field list
        return {"!type": type(value).__name__, **yaml_load(data=yaml_dump_typed(value))}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    return value


# Fields left out of the content while at their defaults, so that a scenario that does not
# use them keeps the hash of study folders written before they existed (and these resume).
# None: the scenario's own fields.
_LATER_FIELDS = {"task": {"z_range": [], "obstacle_spacing": 0.45, "grid_objects": 0,
                          "grasps_per_object": 1, "obstacle_starts": []},
                 "operator": {"reposition_time": 4.0}, None: {"likely_paths": 3},
                 "robot": {"hardware": None, "ready_tool_pose": None, "singular_margin": 0.0,
                           "limit_margin": 0.0},
                 "dmp": {"primitive": ""},
                 "goal_estimator": {"group_mass": 0.0, "commit_radius": 0.05,
                                    "commit_probability": 0.8,
                                    "intent_filter": plain(IntentFilterSettings())}}
# The scenario's fields in the order of the one type that once served the 2-D scenes and the
# robot tasks alike, and the values the fields of the other kind held there: a scenario's
# content is written so, so that study folders keep their hash and their study.json.
_ONE_TYPE_ORDER = ("name", "duration", "robot", "start", "goals", "demonstration",
                   "obstacles", "operator", "task", "seed", "simulator", "likely_paths")
_OTHER_KIND_VALUES = {"start": [], "goals": [], "demonstration": None, "obstacles": [],
                      "task": None}
# A station's field renamed since folders were written: hashed under its old name, so that
# those folders keep their hash (an arm's station fields are the robot's own).
_HASHED_AS = {"control_period": "command_period"}


def _may_reposition(content):
    """Whether the virtual participant may meet a target the tool cannot point at (an arm;
    objects at heights of their own): `reposition_time` then acts, and stays in the hash."""
    robot, task = content.get("robot"), content.get("task")
    return ((isinstance(robot, dict) and robot.get("!type") == "Arm")
            or (isinstance(task, dict) and bool(task.get("z_range"))))


def scenario_content(scenario):
    """Everything in the scenario but its method and seed (set per trial), as plain data."""
    typed = plain(dataclasses.replace(scenario, method="", seed=0))
    content = {"!type": "Scenario"}
    content.update((key, value) for key, value in typed.items()
                   if key not in _ONE_TYPE_ORDER and key != "!type")
    for key in _ONE_TYPE_ORDER:
        if key in typed or key in _OTHER_KIND_VALUES:
            content[key] = typed.get(key, _OTHER_KIND_VALUES.get(key))
    for section, fields in _LATER_FIELDS.items():
        values = content if section is None else content.get(section)
        for name, default in fields.items():
            if (section, name) == ("operator", "reposition_time") and _may_reposition(content):
                continue
            if isinstance(values, dict) and values.get(name, default) == default:
                values.pop(name, None)
    dmp = content.get("dmp")
    if isinstance(dmp, dict) and dmp.get("primitive"):
        # What the trials run is the primitive's content, wherever its file is.
        dmp["primitive"] = _file_digest(dmp["primitive"])
    robot = content.get("robot")
    station = robot.get("station") if isinstance(robot, dict) else None
    for section in (robot, station):
        if isinstance(section, dict):
            for name, old_name in _HASHED_AS.items():
                if name in section:
                    section[old_name] = section.pop(name)
    return content


def content_differences(held, ours, words=("there", "here"), most=3):
    """Where two `scenario_content`s differ, as "FIELD X there, Y here" (`words` name the
    two; dotted paths under `scenario:`, at most `most` of them, then how many more), each
    led by "; " to end a refusal's bracket; "" when the first is not a mapping (a
    study.json written before it was kept)."""
    if not isinstance(held, dict):
        return ""
    found = []

    def walk(there, here, path):
        if isinstance(there, dict) and isinstance(here, dict) and (
                there.get("!type") == here.get("!type")):
            for key in sorted(set(there) | set(here)):
                walk(there.get(key), here.get(key), f"{path}.{key}" if path else key)
        elif there != here:
            found.append(f"{path or 'scenario'} {_shown(there)} {words[0]}, {_shown(here)} "
                         f"{words[1]}")

    walk(held, ours, "")
    more = len(found) - most
    return "".join(f"; {text}" for text in found[:most]) + (f"; {more} more" if more > 0
                                                              else "")


def _shown(value):
    """A value of scenario_content in a message: a typed section by its tag, else JSON."""
    if isinstance(value, dict) and "!type" in value:
        return "!" + value["!type"]
    text = json.dumps(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _file_digest(path):
    """The sha256 of a file's bytes (the path itself when unreadable: resolving refuses it)."""
    try:
        return "sha256:" + hashlib.sha256(pathlib.Path(path).read_bytes()).hexdigest()
    except OSError:
        return path


def scenario_hash(scenario):
    """A short hash of `scenario_content`, so that one folder never mixes two scenarios."""
    text = json.dumps(scenario_content(scenario), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


# ---------------------------------------------------------------------------------------------
# Writing


def trial_paths(output, method, seed):
    """The JSON and CSV files of one trial."""
    folder = pathlib.Path(output) / "trials" / method
    return folder / f"seed_{seed}.json", folder / f"seed_{seed}.csv"


def trial_seed(path):
    """The seed a trial file's name gives (`seed_N.json`, `seed_N.csv`: `trial_paths`), or
    None for another name."""
    stem = pathlib.Path(path).stem
    number = stem[len("seed_"):]
    return int(number) if stem.startswith("seed_") and number.isdigit() else None


def trials_left_out(output, methods, trials, seed):
    """What a study of `methods` over seeds `seed` to `seed + trials - 1` leaves out of the
    trial files in `output`: "pbp_continuous (30 trials); 2 trials of the others outside
    seeds 10000 to 10009", or "" when it covers them all."""
    root = pathlib.Path(output) / "trials"
    other_methods, outside = [], 0
    for folder in sorted(root.iterdir() if root.is_dir() else []):
        seeds = [value for value in map(trial_seed, folder.glob("seed_*.json"))
                 if value is not None]
        if seeds and folder.name not in methods:
            other_methods.append(f"{folder.name} ({counted(len(seeds), 'trial')})")
        elif seeds:
            outside += sum(not seed <= value < seed + trials for value in seeds)
    return "; ".join(other_methods + ([
        f"{counted(outside, 'trial')} of the others outside seeds {seed} to "
        f"{seed + trials - 1}"] if outside else []))


def running_marker(output, method, seed):
    """Present while a process runs the trial: after a worker dies, it tells which had begun."""
    return trial_paths(output, method, seed)[0].with_suffix(".running")


def json_float(value):
    """A float for JSON: None for NaN and infinities (JSON has no NaN)."""
    if value is None:
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def trial_record(scenario_name, digest, method, trial, seed):
    """A trial's record before it runs: not successful, no metrics, no error."""
    return {"format": TRIAL_FORMAT, "scenario": scenario_name, "scenario_hash": digest,
            "method": method, "trial": trial, "seed": seed, "success": False,
            "task_time": None, "intervention_ratio": None, "switches": None,
            "collision_ratio": None, "peak_hand_speed": None,
            "peak_command_acceleration": None,
            **dict.fromkeys(INTERACTION_METRICS), "ticks": 0, "objects": None,
            "targets": None, "time_series": None, "error": None, "drake_warnings": 0,
            "wall_time": None}


def interaction_fields(result):
    """The interaction metrics of a TaskResult as a trial record's JSON fields."""
    fields = {}
    for name in INTERACTION_METRICS:
        value = getattr(result, name)
        if name == "time_to_prediction":
            value = None if value is None else [json_float(t) for t in value]
        elif name == "unpredicted_switches":
            value = None if value is None else int(value)
        else:
            value = json_float(value)
        fields[name] = value
    return fields


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


def write_study(output, scenario, digest, methods, trials, seed, split=None,
                scenario_file=None, split_seeds=None, participant_condition=None,
                overrides=None, participant=None):
    """Writes the folder's study.json: which scenario, methods, trials and seeds, and the
    split the seeds belong to (`studies.splits`; None when not known). Written when not
    None: `scenario_file` (the path the study was run from), `split_seeds` ({"tuning":
    first seed, "evaluation": first seed}), `participant_condition` and `overrides`
    (`ScenarioOverrides.record()`), with which `report --markdown` names the command, and
    `participant`, the ID of a user study's participant whose session the folder holds."""
    study = {"study": METHOD_COMPARISON, "format": TRIAL_FORMAT, "scenario": scenario.name,
             "scenario_hash": digest, "methods": list(methods), "trials": trials, "seed": seed,
             "split": split, "scenario_content": scenario_content(scenario)}
    write_study_json(output, study, scenario_file, split_seeds, participant_condition,
                     overrides, participant)


def write_study_json(output, study, scenario_file=None, split_seeds=None,
                     participant_condition=None, overrides=None, participant=None):
    """Writes the dict `study` and the optional fields given (`write_study`) as study.json."""
    if participant is not None:
        study["participant"] = str(participant)
    if scenario_file is not None:
        study["scenario_file"] = str(scenario_file)
    if split_seeds is not None:
        study["split_seeds"] = dict(split_seeds)
    if participant_condition is not None:
        study["participant_condition"] = str(participant_condition)
    if overrides is not None:
        study["overrides"] = overrides
    write_atomically(pathlib.Path(output) / "study.json", json.dumps(study, indent=2) + "\n")


# ---------------------------------------------------------------------------------------------
# Reading

# A damaged or foreign file of a study folder: its path and what is wrong with it. `key` is
# the trial's (method, trial) when the file belongs to one (None for study.json).
Damage = collections.namedtuple("Damage", "path problem key", defaults=(None,))
# The JSON types of a trial record's fields (None is allowed for all but these first ones).
_REQUIRED = {"success": (bool,), "method": (str,), "seed": (int,)}
_NUMBER = (int, float)
_TYPES = {"scenario": (str,), "scenario_hash": (str,), "trial": (int,), "task_time": _NUMBER,
          "intervention_ratio": _NUMBER, "switches": (int,), "collision_ratio": _NUMBER,
          "peak_hand_speed": _NUMBER, "peak_command_acceleration": _NUMBER,
          "posterior_clipped_ratio": _NUMBER, "ticks": (int,),
          **dict.fromkeys(INTERACTION_METRICS, _NUMBER), "time_to_prediction": (list,),
          "unpredicted_switches": (int,),
          "objects": (list,), "targets": (list,), "time_series": (str,), "error": (str,)}
_INTEGER_COLUMNS = {"operator_active", "selected_goal", "target", "in_collision"}


class DamagedFile(ValueError):
    """A trial or study file that cannot be read: truncated, empty, malformed."""


def _type_name(value):
    return "null" if value is None else type(value).__name__


def record_problem(record):
    """What is wrong with the types of a trial record's fields, or None."""
    if not isinstance(record, dict):
        return f"holds a {_type_name(record)}, not a trial record"
    for field, types in {**_REQUIRED, **_TYPES}.items():
        value = record.get(field)
        if value is None and field not in _REQUIRED:
            continue
        if isinstance(value, bool) and bool not in types or not isinstance(value, types):
            wanted = " or ".join(t.__name__ for t in types)
            return f"field {field!r} is {_type_name(value)} {value!r:.40}, not {wanted}"
    return None


def read_time_series(path, ticks=None):
    """A trial's CSV as a dict of arrays keyed by column name. Raises DamagedFile when it is
    empty or malformed (or has not `ticks` rows, when given)."""
    if is_special_file(path):
        raise DamagedFile(f"{path}: a device or a pipe, not a regular file")
    if pathlib.Path(path).stat().st_size > MOST_READ_BYTES:
        raise DamagedFile(f"{path}: holds more than {MOST_READ_BYTES:,} bytes, not a trial's "
                          "time series")
    try:
        with open(path, newline="") as stream:
            reader = csv.reader(stream)
            columns = next(reader, None)
            rows = list(reader)
    except (UnicodeDecodeError, csv.Error) as error:
        raise DamagedFile(f"{path}: malformed CSV ({error})") from None
    if not columns:
        raise DamagedFile(f"{path}: empty CSV (no header)")
    # A grasping trial written before the hand's orientation was logged ends without it.
    grasp = time_series_columns(False, has_grasp=True)
    if columns not in (time_series_columns(False), time_series_columns(True), grasp,
                       grasp[:-len(HAND_ORIENTATION_COLUMNS)]):
        raise DamagedFile(f"{path}: malformed CSV: its header is not a trial's time series")
    for number, row in enumerate(rows, start=2):
        if len(row) != len(columns):
            raise DamagedFile(f"{path}: malformed CSV: line {number} has {len(row)} fields, "
                              f"not {len(columns)} (truncated?)")
    if ticks is not None and len(rows) != ticks:
        raise DamagedFile(f"{path}: truncated CSV: {len(rows)} rows, the trial has {ticks} "
                          "ticks")
    data = {}
    for index, name in enumerate(columns):
        values = [row[index] for row in rows]
        try:
            data[name] = (np.array(values, dtype=int) if name in _INTEGER_COLUMNS
                          else np.array(values, dtype=float))
        except ValueError as error:
            raise DamagedFile(f"{path}: malformed CSV: column {name!r}: {error}") from None
    return data


def load_task_result(output, method, seed):
    """The TaskResult of a finished trial, read back from its JSON and CSV files."""
    json_path, csv_path = trial_paths(output, method, seed)
    try:
        record = json.loads(read_text(json_path))
    except ValueError as error:
        raise DamagedFile(f"{json_path}: truncated or invalid JSON ({error})") from None
    problem = record_problem(record)
    if problem is not None:
        raise DamagedFile(f"{json_path}: {problem}")
    if record["error"] is not None:
        raise ValueError(f"{json_path}: the trial failed: {record['error']}")
    series = read_time_series(csv_path)

    def stacked(*columns):
        return np.column_stack([series[column] for column in columns])

    in_collision = series["in_collision"].astype(bool) if "in_collision" in series else None
    grasp = {}
    if "angle_to_target" in series:  # the grasping task's orientation columns
        grasp = dict(
            angles_to_target=series["angle_to_target"],
            command_angular_velocities=stacked("command_wx", "command_wy", "command_wz"),
            operator_twists=stacked("operator_vx", "operator_vy", "operator_vz",
                                    "operator_wx", "operator_wy", "operator_wz"))
        if HAND_ORIENTATION_COLUMNS[0] in series:
            grasp["hand_orientations"] = stacked(*HAND_ORIENTATION_COLUMNS)
    return TaskResult(
        success=record["success"], task_time=record["task_time"],
        intervention_ratio=record["intervention_ratio"], switches=record["switches"],
        times=series["time"], ee_positions=stacked("ee_x", "ee_y", "ee_z"),
        headings=series["heading"],
        commands=stacked("command_x", "command_y", "command_z", "command_vx", "command_vy",
                         "command_vz", "command_heading"),
        operator_active=series["operator_active"].astype(bool),
        operator_commands=stacked("operator_vx", "operator_vy", "operator_vz",
                                  "operator_yaw_rate"),
        selected_goals=series["selected_goal"], targets=series["target"],
        objects=np.array(record["objects"], float),
        collision_ratio=record["collision_ratio"], in_collision=in_collision,
        peak_hand_speed=record.get("peak_hand_speed"),
        peak_command_acceleration=record.get("peak_command_acceleration"),
        peak_command_angular_change=record.get("peak_command_angular_change"),
        **{name: record.get(name) for name in INTERACTION_METRICS}, **grasp)


def read_trial(output, method, seed, digest, damaged=None, key=None):
    """A trial's JSON record if it is on disk and whole, else None. A damaged trial (bad
    JSON or field types, an empty, malformed or missing CSV) or one of another format is
    appended to `damaged` as a Damage (when given) and reads as None: it runs again. One of
    another scenario than `digest` raises StudyFolderError, unless `damaged` is given."""
    json_path, csv_path = trial_paths(output, method, seed)

    def bad(path, problem):
        if damaged is not None:
            damaged.append(Damage(str(path), problem, key))

    if not json_path.exists():
        return None
    record, problem = read_json(json_path)
    problem = problem or record_problem(record)
    if problem is None and record.get("format") != TRIAL_FORMAT:
        problem = f"a trial of format {record.get('format')!r}, not {TRIAL_FORMAT}"
    if problem is None and (record["method"] != method or record["seed"] != seed):
        problem = f"holds the trial of {record['method']!r}, seed {record['seed']}"
    if problem is not None:
        return bad(json_path, problem)
    if digest is not None and record.get("scenario_hash") != digest:
        message = (f"a trial of another scenario ({record.get('scenario')!r}, hash "
                   f"{record.get('scenario_hash')}, not {digest})")
        if damaged is None:
            raise StudyFolderError(f"{json_path} is {message}: choose another --output folder")
        return bad(json_path, message)
    if record["error"] is None:
        if not csv_path.exists():
            return bad(csv_path, "missing: the trial's time series CSV is not on disk")
        try:
            read_time_series(csv_path, record.get("ticks"))
        except DamagedFile as error:
            return bad(csv_path, str(error).removeprefix(f"{csv_path}: "))
        except OSError as error:
            return bad(csv_path, f"unreadable ({error.strerror})")
    return record


def study_problem(study):
    """What makes a parsed study.json not a method comparison's, or None."""
    if not isinstance(study, dict):
        return f"holds a {_type_name(study)}, not a study"
    if study.get("study") != METHOD_COMPARISON:
        return f"a study.json of another kind ({study.get('study')!r}, not 'method_comparison')"
    methods, trials, seed = study.get("methods"), study.get("trials"), study.get("seed")
    if not (isinstance(methods, list) and methods and all(isinstance(m, str) for m in methods)):
        return "field 'methods' is not a list of method names"
    for field, value in (("trials", trials), ("seed", seed)):
        if isinstance(value, bool) or not isinstance(value, int):
            return f"field {field!r} is {_type_name(value)}, not int"
    if trials < 1:
        return f"field 'trials' is {trials}, not a positive number"
    if not isinstance(study.get("split"), (str, type(None))):
        return f"field 'split' is {_type_name(study.get('split'))}, not str"
    for field in ("scenario", "scenario_hash"):
        if not isinstance(study.get(field), str):
            return f"field {field!r} is {_type_name(study.get(field))}, not str"
    return None


def infer_study(output):
    """The study a folder's trial files describe, without study.json: every method folder
    under trials/ (by name), the seeds from the lowest to the highest on disk, and the
    scenario most readable trials name. None when there are no trial files."""
    seeds, methods, hashes = set(), [], collections.Counter()
    for folder in sorted(p for p in (output / "trials").glob("*") if p.is_dir()):
        found = [p for p in folder.glob("seed_*.*") if p.suffix in (".json", ".csv")]
        numbers = {trial_seed(p) for p in found} - {None}
        if numbers:
            methods.append(folder.name)
            seeds |= numbers
        for path in found:
            record = read_json(path)[0] if path.suffix == ".json" else None
            if isinstance(record, dict) and isinstance(record.get("scenario_hash"), str):
                hashes[(record["scenario_hash"], str(record.get("scenario")))] += 1
    if not methods:
        return None
    (digest, name), _ = hashes.most_common(1)[0] if hashes else ((None, None), 0)
    return {"study": METHOD_COMPARISON, "format": TRIAL_FORMAT, "scenario": name,
            "scenario_hash": digest, "methods": methods, "seed": min(seeds),
            "trials": max(seeds) - min(seeds) + 1}


def read_study(output):
    """`(study, records, damaged)` of a study folder: its study.json (else `infer_study`),
    `{(method, trial): record}` (None for a trial not on disk or damaged) and a Damage for
    every damaged or foreign file. Raises StudyFolderError when there is neither a
    study.json nor any trial file."""
    output = pathlib.Path(output)
    study_path = output / "study.json"
    damaged = []
    study, problem = read_json(study_path)
    problem = problem or study_problem(study)
    if problem is not None:
        study = infer_study(output)
        if study is None:
            raise StudyFolderError(
                f"{output} has no study.json of a method comparison ({study_path}: {problem}) "
                "and no trial files: is it the --output folder of a `pbp-drake study`?")
        damaged.append(Damage(str(study_path), f"{problem}; reporting the trials on disk"))
    records = {}
    for method in study["methods"]:
        for trial in range(study["trials"]):
            records[(method, trial)] = read_trial(output, method, study["seed"] + trial,
                                                  study["scenario_hash"], damaged,
                                                  (method, trial))
    return study, records, damaged


def name_damaged(damaged):
    """Names each damaged or foreign file on stderr: its path and what is wrong."""
    for item in damaged:
        print(f"pbp-drake: damaged: {item.path}: {item.problem}", file=sys.stderr, flush=True)
