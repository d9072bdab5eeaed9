"""`pbp-drake report DIR --markdown FILE`: a study folder's results as a Markdown fragment
for the docs, first the command that made the study, read off the folder so that a table
cannot name other seeds or methods than its own, then its table.
"""

import json
import pathlib

from pbp_drake.scenarios import METHOD_NAMES, ScenarioError
from pbp_drake.scenarios.overrides import ScenarioOverrides
from pbp_drake.scenarios.schema import alpha_key
from pbp_drake.studies.report import results_table
from pbp_drake.studies.splits import SPLITS
from pbp_drake.studies.toy import TOY_FIGURES
from pbp_drake.studies.atomic_files import (
    is_disk_failure, read_json, read_text, write_atomically)
from pbp_drake.studies.trial_files import StudyError, write_study_json


def write_toy_study(output, kind, scenario_name, scenario_file, overrides=None):
    """Writes a 2-D study folder's study.json, which names the command that made it."""
    write_study_json(output, {"study": kind, "scenario": scenario_name}, scenario_file,
                     overrides=overrides)


def _scenario_file(study, summary):
    recorded = study.get("scenario_file") if isinstance(study, dict) else None
    return recorded or f"<the scenario file of {summary.get('scenario')}>"


def study_command(study, summary):
    """The `pbp-drake study` command that made a method comparison (without --output and
    --jobs): its seeds by `--split` when the split starts at its first seed, else `--seed`."""
    seed, trials = summary["seed"], summary["trials"]
    words = ["pbp-drake study", _scenario_file(study, summary),
             "--methods", ",".join(summary["methods"]), "--trials", str(trials)]
    split = summary.get("split")
    split_seeds = study.get("split_seeds") or {}
    if split in SPLITS and split_seeds.get(split) == seed:
        words += ["--split", split]
    else:
        words += ["--seed", str(seed)]
    condition = study.get("participant_condition")
    if isinstance(condition, str):
        words += ["--participant-condition", condition]
    return " ".join(words + _override_words(study))


def _override_words(study):
    """The recorded `--scenario-text` and `--set` flags, as typed ([] for none)."""
    recorded = study.get("overrides") if isinstance(study, dict) else None
    if not isinstance(recorded, dict):
        return []
    settings = recorded.get("set") or []
    text = recorded.get("scenario_text")
    if not all(isinstance(setting, str) for setting in settings) or not isinstance(
            text, (str, type(None))):
        return []
    try:
        return [ScenarioOverrides(tuple(settings), text).words()]
    except ScenarioError:  # a study.json edited by hand: the command without them
        return []


def _seeds_text(summary):
    first, last = summary["seeds"]
    split = summary.get("split")
    label = f"{split} seeds" if split else "seeds (no split recorded)"
    return f"{label} {first:,} to {last:,}"


def method_comparison_markdown(study, summary):
    """The command and seeds line, then results.md's table."""
    return (f"`{study_command(study, summary)}` — {_seeds_text(summary)}\n\n"
            + results_table(summary))


def _toy_command(study, summary):
    return " ".join([f"pbp-drake study {_scenario_file(study, summary)}",
                     *_override_words(study)])


def _outcome_cell(outcome):
    reached = "yes" if outcome["reached"] else "no"
    return f"{outcome['collision_ratio']:.3f} / {reached}"


def alpha_study_markdown(study, summary, figure):
    """One row per scene and operator speed: the ideal alpha, then the collision ratio and
    whether the goal was reached, for each fixed alpha and PBP mode."""
    alphas = [alpha_key(alpha) for alpha in summary["alphas"]]
    speeds = ", ".join("-" if s is None else f"{s:g}" for s in summary["operator_speeds"])
    lines = [f"`{_toy_command(study, summary)}` — the 2-D alpha study (Fig. 2): "
             f"{len(summary['scenes'])} scenes at operator speeds {speeds}", "",
             "Each cell: collision ratio / goal reached (within "
             f"{summary['goal_tolerance']:g}). Ideal alpha: {summary['ideal_alpha_criterion']}.",
             ""]
    columns = ["scene", "operator speed", "ideal alpha",
               *(f"alpha {alpha}" for alpha in alphas), "PBP-Alt", "PBP-Cont"]
    lines += ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for scene in summary["scenes"]:
        for key, results in scene["by_operator_speed"].items():
            ideal = results["ideal_alpha"]
            cells = [scene["name"], key, "none" if ideal is None else f"{ideal:g}",
                     *(_outcome_cell(results["fixed_alpha"][alpha]) for alpha in alphas),
                     _outcome_cell(results["pbp_alternated"]),
                     _outcome_cell(results["pbp_continuous"])]
            lines.append("| " + " | ".join(cells) + " |")
    lines += ["", f"Figure: `{figure}`."]
    return "\n".join(lines) + "\n"


def alt_vs_cont_markdown(study, summary, figure):
    """One row per mode: its final error and how its phase moved while the operator acted."""
    lines = [f"`{_toy_command(study, summary)}` — PBP-Cont against PBP-Alt on the same DMP "
             "and open-loop input (Fig. 4)", ""]
    columns = ["method", "final error (cm)", "input stopped at (s)",
               "phase constant while the operator acts", "phase strictly increasing"]
    lines += ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for method, mode in summary["modes"].items():
        cells = [METHOD_NAMES.get(method, method), f"{100 * mode['final_error']:.2f}",
                 f"{mode['input_stopped_at']:.2f}",
                 "yes" if mode["phase_constant_while_operator_acts"] else "no",
                 "yes" if mode["phase_strictly_increasing"] else "no"]
        lines.append("| " + " | ".join(cells) + " |")
    both = "yes" if summary["both_reach_goal"] else "no"
    lines += ["", f"Both reach the goal (within {summary['goal_tolerance']:g}): {both}.", "",
              f"Figure: `{figure}`."]
    return "\n".join(lines) + "\n"


def toy_markdown(output):
    """The Markdown of a 2-D study folder; StudyError when its summary.json is unreadable."""
    output = pathlib.Path(output)
    try:
        summary = json.loads(read_text(output / "summary.json"))
    except (OSError, ValueError) as error:
        raise StudyError(f"{output / 'summary.json'}: cannot be read ({error})") from None
    study = read_study_json(output)  # {} when the folder has none
    figure = output / TOY_FIGURES[summary["study"]]
    if summary["study"] == "alpha_study":
        return alpha_study_markdown(study, summary, figure)
    return alt_vs_cont_markdown(study, summary, figure)


def read_study_json(output):
    """A study folder's study.json as a dict ({} when missing or unreadable)."""
    study, _ = read_json(pathlib.Path(output) / "study.json")
    return study if isinstance(study, dict) else {}


def check_markdown_path(path):
    """Raises StudyError when `path` cannot take the Markdown file (a folder)."""
    path = pathlib.Path(path)
    if path.is_dir():
        raise StudyError(f"--markdown {path}: is a folder; give a file name, e.g. "
                         f"{path / 'results.md'}")


def write_markdown(path, text):
    """Writes the fragment to `path`; StudyError when it cannot (a disk's failure as is)."""
    path = pathlib.Path(path)
    try:
        write_atomically(path, text)
    except OSError as error:
        if is_disk_failure(error) or isinstance(error, BrokenPipeError):  # `| head`: quiet
            raise
        raise StudyError(f"--markdown {path}: cannot be written ({error.strerror})") from None
