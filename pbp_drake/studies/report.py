"""`pbp-drake report DIR`: a study folder's `summary.json`, `results.md`, `trials.json` and
figures, rebuilt from its study.json and trial files only (no simulation)."""

import json
import pathlib

from pbp_drake.scenarios import METHOD_NAMES, counted
from pbp_drake.studies.figures import plot_collision_histogram, plot_intervention, plot_task_time
from pbp_drake.studies.intervals import INTERACTION_MEANS, confidence_table
from pbp_drake.studies.splits import seeds_line
from pbp_drake.studies.summary import summarize
from pbp_drake.studies.atomic_files import write_atomically
from pbp_drake.studies.trial_files import TRIAL_FIELDS, name_damaged, read_study

BOX_FIGURES = ("fig7a_intervention.png", "fig7b_task_time.png")
COLLISION_FIGURE = "fig7c_collisions.png"


def figure_names(summary):
    """The figures `report` writes: Fig. 7a and 7b, and 7c where collisions are measured."""
    return BOX_FIGURES + ((COLLISION_FIGURE,) if summary["measures_collisions"] else ())


def _cell(entry, field, digits):
    """`mean ± std`; `mean (n = 1)` when a single trial had a value (no spread)."""
    value = entry[field]
    if value["mean"] is None:
        return "-"
    if value["std"] is None:
        return f"{value['mean']:.{digits}f} (n = 1)"
    return f"{value['mean']:.{digits}f} ± {value['std']:.{digits}f}"


def _peak_cell(entry, field, digits):
    """`max / mean` of a per-trial peak; n/a when no trial recorded it."""
    value = entry[field]
    if value["max"] is None:
        return "n/a"
    return f"{value['max']:.{digits}f} / {value['mean']:.{digits}f}"


def interaction_table(summary):
    """The Markdown lines of the interaction metrics (`INTERACTION_MEANS`), one row per
    method: mean ± std of each, and the switches never named of all; [] when none has any."""
    methods = summary["methods"]
    if not any(name in entry for entry in methods.values() for name, *_ in INTERACTION_MEANS):
        return []
    columns = ["method", *(column for _, column, _, _ in INTERACTION_MEANS),
               "switches never named"]
    lines = ["How the operator and the method worked together (mean ± std over the trials "
             "with a value; see the docs' study page for each definition).", "",
             "| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for method, entry in methods.items():
        cells = [METHOD_NAMES.get(method, method)]
        for name, _, digits, _ in INTERACTION_MEANS:
            cells.append(_cell(entry, name, digits) if name in entry else "-")
        latency = entry.get("time_to_prediction") or {}
        switches = latency.get("switches")
        cells.append(f"{latency['unpredicted_switches']} of {switches}" if switches else "-")
        lines.append("| " + " | ".join(cells) + " |")
    return lines


# The units of the impairment's fields in the results' words.
_IMPAIRMENT_UNITS = {"command_noise_time": " s", "command_delay": " s", "mistake_time": " s"}


def participant_line(summary):
    """One line for results: how the virtual participant was impaired, or "" when it was not."""
    participant = summary.get("virtual_participant")
    if not participant:
        return ""
    fields = ", ".join(f"{name} {value:g}{_IMPAIRMENT_UNITS.get(name, '')}"
                       for name, value in participant["impairment"].items())
    condition = participant["condition"]
    head = (f"Virtual participant: the {condition} condition" if condition
            else "Virtual participant: impaired")
    return head + (f" ({fields})." if fields else ".")


def results_table(summary):
    """The summary (`summarize`) as results.md: the seeds and `participant_line`, a table
    with a row per method (mean ± std of each mean, max / mean of each peak), then
    `interaction_table` and `intervals.confidence_table`."""
    seeds = seeds_line(summary)
    lines = [seeds, ""] if seeds else []
    participant = participant_line(summary)
    if participant:
        lines += [participant, ""]
    collisions = summary["measures_collisions"]
    clipped = any("posterior_clipped_ratio" in e for e in summary["methods"].values())
    columns = ["method", "trials", "success", "intervention ratio", "task time (s)",
               *(("collision ratio", "collision-free trials") if collisions else ()),
               "peak hand speed (m/s), max / mean",
               "peak command acceleration (m/s²), max / mean",
               *(("posterior at its clip",) if clipped else ()), "errors"]
    lines += ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for method, entry in summary["methods"].items():
        rate = "-" if entry["success_rate"] is None else f"{100 * entry['success_rate']:.0f} %"
        gone = [f"{entry[k]} {k}" for k in ("missing", "damaged") if entry.get(k)]
        trials = f"{entry['trials']}" + (f" ({', '.join(gone)})" if gone else "")
        collision = ()
        if collisions:
            free = entry["collision_free_trials"]
            collision = (_cell(entry, "collision_ratio", 3), "-" if free is None else str(free))
        cells = [METHOD_NAMES.get(method, method), trials, rate,
                 _cell(entry, "intervention_ratio", 3), _cell(entry, "task_time", 1),
                 *collision, _peak_cell(entry, "peak_hand_speed", 3),
                 _peak_cell(entry, "peak_command_acceleration", 2),
                 *((_cell(entry, "posterior_clipped_ratio", 3)
                    if "posterior_clipped_ratio" in entry else "-",) if clipped else ()),
                 str(entry["errors"])]
        lines.append("| " + " | ".join(cells) + " |")
    interaction = interaction_table(summary)
    if interaction:
        lines += ["", *interaction]
    lines += ["", *confidence_table(summary)]
    if summary.get("damaged"):
        files = counted(len(summary["damaged"]), "file")
        trials = counted(sum(e.get("damaged", 0) for e in summary["methods"].values()), "trial")
        lines += ["", f"Skipped as damaged or foreign: {files} ({trials}); see summary.json."]
    arbitration = summary.get("arbitration")
    if arbitration is not None:
        ideal = arbitration["ideal_alpha"]
        lines += ["", f"Ideal fixed alpha: {'none' if ideal is None else ideal} "
                      f"({arbitration['criterion']})."]
    return "\n".join(lines) + "\n"


def flat_trials(study, records):
    """trials.json's rows: each trial on disk, its `TRIAL_FIELDS` (None where it has none)."""
    rows = []
    for method in study["methods"]:
        for trial in range(study["trials"]):
            record = records[(method, trial)]
            if record is not None:
                rows.append({field: record.get(field) for field in TRIAL_FIELDS})
    return rows


def report(output):
    """Rebuilds `summary.json`, `results.md`, `trials.json` and the figures of a study folder
    (`figure_names`) from its study.json and trial files only (no simulation). Returns the
    summary. Damaged or foreign files (`read_study`) are named on stderr and skipped."""
    output = pathlib.Path(output)
    study, records, damaged = read_study(output)
    name_damaged(damaged)
    summary = summarize(study, records, damaged, output)
    write_atomically(output / "summary.json", json.dumps(summary, indent=2) + "\n")
    write_atomically(output / "results.md", results_table(summary))
    write_atomically(output / "trials.json",
                     json.dumps(flat_trials(study, records), indent=1) + "\n")
    rows = [r for r in records.values() if r is not None]
    methods = study["methods"]
    plot_intervention(rows, methods, output / BOX_FIGURES[0])
    plot_task_time(rows, methods, output / BOX_FIGURES[1])
    if summary["measures_collisions"]:
        plot_collision_histogram(summary, output / COLLISION_FIGURE)
    else:
        # A Fig. 7c left in the folder (all zeros: nothing measured) would read as a result.
        (output / COLLISION_FIGURE).unlink(missing_ok=True)
    return summary
