"""`pbp-drake report DIR` of a matrix folder (`studies.matrix`): its `summary.json`,
`trials.json`, the method x pilot tables of `results.md` (every mean a method entry holds,
with its 95 % interval, and every method against PBP-Alt paired by seed) and the figure
`pilots.png`, rebuilt from the pilots' trial files only.
"""

import json
import math
import pathlib

from pbp_drake.scenarios import METHOD_NAMES, counted
from pbp_drake.studies.figures import plot_pilot_panels
from pbp_drake.studies.intervals import MEAN_METRICS, mean_interval, wilson_interval
from pbp_drake.studies.matrix import read_matrix, summarize_matrix
from pbp_drake.studies.paired import paired_rows_with
from pbp_drake.studies.report import flat_trials
from pbp_drake.studies.results_markdown import study_command, write_markdown
from pbp_drake.studies.splits import seeds_line
from pbp_drake.studies.atomic_files import write_atomically

FIGURE = "pilots.png"
#: The method every other is paired with, pilot by pilot, when the matrix ran it.
REFERENCE = "pbp_alternated"
# Column names and digits of the metrics the studies' tables already name; a metric not
# among them is shown by its field's name with 3 decimals, its interval uncut.
_KNOWN = {key: (column, digits, within) for key, column, digits, within in MEAN_METRICS}


def mean_metrics(summary):
    """The method entries' metrics that are means (`{"mean", "std"}`), in first-met order."""
    names = []
    for pilot in summary["pilots"].values():
        for entry in pilot["methods"].values():
            for key, value in entry.items():
                if isinstance(value, dict) and {"mean", "std"} <= set(value) and (
                        key not in names):
                    names.append(key)
    return names


def metric_range(key):
    """The range a metric's values lie in (its interval is cut to it); unknown: unbounded."""
    return _KNOWN[key][2] if key in _KNOWN else (-math.inf, math.inf)


def metric_label(key):
    """A metric's name in the tables."""
    return _KNOWN[key][0] if key in _KNOWN else key.replace("_", " ")


def _finite_count(records, method, key):
    """How many of the method's trials that ran hold a finite `key` (None: none)."""
    values = [record.get(key) for (name, _), record in records.items()
              if name == method and record is not None and record.get("error") is None]
    numbers = [v for v in values if isinstance(v, (int, float)) and not isinstance(v, bool)
               and math.isfinite(v)]
    return len(numbers) if numbers else None


def metric_interval(entry, key, count):
    """`(mean, low, high)` of a method entry's metric: the entry's own interval, else the
    mean's 95 % t interval over `count` values (the entry's count where it has one) within
    `metric_range`; low and high None with fewer than two values, all None without a mean."""
    value = entry.get(key)
    if not isinstance(value, dict) or value.get("mean") is None:
        return None, None, None
    if "interval" in value:
        interval = value["interval"]
    else:
        interval = mean_interval(value["mean"], value["std"], value.get("count", count),
                                 metric_range(key))
    return (value["mean"], *(interval or (None, None)))


def success_interval(entry):
    """`(rate, low, high)` of a method entry's success rate (Wilson's interval), or Nones."""
    rate = entry["success_rate"]
    if rate is None:
        return None, None, None
    return (rate, *wilson_interval(round(rate * entry["trials"]), entry["trials"]))


def interval_table(summary, records_by_pilot):
    """`{metric: {pilot: {method: (mean, low, high)}}}` of "success" and `mean_metrics`."""
    table = {"success": {pilot: {method: success_interval(entry)
                                 for method, entry in data["methods"].items()}
                         for pilot, data in summary["pilots"].items()}}
    for key in mean_metrics(summary):
        table[key] = {}
        for pilot, data in summary["pilots"].items():
            records = records_by_pilot[pilot]
            table[key][pilot] = {}
            for method, entry in data["methods"].items():
                ran = entry["trials"] - entry["errors"]
                count = _finite_count(records, method, key)
                table[key][pilot][method] = metric_interval(
                    entry, key, ran if count is None else count)
    return table


def _cell(interval, digits, percent=False):
    mean, low, high = interval
    if mean is None:
        return "-"
    scale, unit = (100, " %") if percent else (1, "")
    text = f"{scale * mean:.{digits}f}"
    if low is not None:
        text += f" [{scale * low:.{digits}f}, {scale * high:.{digits}f}]"
    return text + unit


def _paired_cell(row):
    if row is None:
        return "-"
    interval = ("" if not math.isfinite(row.high) else
                f" [{row.low:+.3g}, {row.high:+.3g}]")
    return f"{row.difference:+.3g}{interval} ({row.pairs})"


def _method_name(method):
    return METHOD_NAMES.get(method, method)


def matrix_tables(summary, intervals, paired, reference):
    """The Markdown of the matrix: the trials per pilot, a table per metric (rows:
    methods, columns: pilots; each cell the mean and its 95 % interval), then a table per
    metric of each method against `reference` under the same pilot, paired by seed."""
    pilots = list(summary["pilots"])
    methods = list(next(iter(summary["pilots"].values()))["methods"])
    header = ["| method | " + " | ".join(pilots) + " |", "|" + "---|" * (len(pilots) + 1)]
    lines = [seeds_line(summary), "",
             f"Every method under every pilot ({', '.join(pilots)}), on the same seeds. Each "
             "cell: the mean over the trials that ran and its 95 % interval (Student's t, "
             "within the metric's range); success: the rate over the trials on disk and "
             "its Wilson interval.", "", "**Trials** (errors, missing)", "", *header]
    for method in methods:
        cells = []
        for pilot in pilots:
            entry = summary["pilots"][pilot]["methods"][method]
            cells.append(f"{entry['trials']} ({entry['errors']}, {entry['missing']})")
        lines.append(f"| {_method_name(method)} | " + " | ".join(cells) + " |")
    for key, by_pilot in intervals.items():
        digits = 0 if key == "success" else _KNOWN.get(key, (None, 3))[1]
        lines += ["", f"**{metric_label(key)}**", "", *header]
        for method in methods:
            cells = [_cell(by_pilot[pilot].get(method, (None, None, None)), digits,
                           percent=key == "success") for pilot in pilots]
            lines.append(f"| {_method_name(method)} | " + " | ".join(cells) + " |")
    if paired is not None:
        name = _method_name(reference)
        lines += ["", f"Each method against {name} under the same pilot, paired by seed: "
                  f"the mean of the method minus {name}, its 95 % interval (Student's t) and "
                  "the number of pairs (a time over the seeds both succeeded on)."]
        others = [m for m in methods if m != reference]
        for key in intervals:
            lines += ["", f"**{metric_label(key)}, against {name}**", "", *header]
            for method in others:
                cells = [_paired_cell(paired[pilot].get((method, key))) for pilot in pilots]
                lines.append(f"| {_method_name(method)} | " + " | ".join(cells) + " |")
    if summary["damaged"]:
        lines += ["", "Skipped as damaged or foreign: "
                      f"{counted(len(summary['damaged']), 'file')}; see summary.json."]
    return "\n".join(lines) + "\n"


def matrix_command(study, summary):
    """The `pbp-drake study` command that made the matrix (without --output and --jobs)."""
    return (study_command(study, {**summary, "methods": study["methods"]})
            + " --pilots " + ",".join(study["pilots"]))


def report_matrix(output, reference=None, markdown=None):
    """Rebuilds a matrix folder's files (the module's docstring) and returns the summary;
    `markdown`: also writes the tables to that file after the command that made the matrix.
    `reference`: the method every other is paired with (default PBP-Alt, when the matrix ran
    it). Raises ValueError when the matrix did not run `reference`."""
    output = pathlib.Path(output)
    study, pilots = read_matrix(output)
    summary = summarize_matrix(study, pilots, output)
    records = {pilot: read[1] for pilot, read in pilots.items()}
    intervals = interval_table(summary, records)
    if reference is None and REFERENCE in study["methods"]:
        reference = REFERENCE
    paired = None
    if reference is not None:
        if reference not in study["methods"]:
            raise ValueError(f"the matrix ran {', '.join(study['methods'])}, not {reference}")
        paired = {}
        for pilot, (pilot_study, pilot_records, _) in pilots.items():
            rows = paired_rows_with(pilot_study, pilot_records, reference,
                                    summary["measures_collisions"], list(intervals))
            paired[pilot] = {(row.method, row.metric): row for row in rows}
    tables = matrix_tables(summary, intervals, paired, reference)
    write_atomically(output / "summary.json", json.dumps(summary, indent=2) + "\n")
    write_atomically(output / "results.md", tables)
    rows = [{"pilot": pilot, **row} for pilot, (pilot_study, pilot_records, _) in pilots.items()
            for row in flat_trials(pilot_study, pilot_records)]
    write_atomically(output / "trials.json", json.dumps(rows, indent=1) + "\n")
    plot_pilot_panels(
        {pilot: [(method, intervals["intervention_ratio"][pilot][method],
                  intervals["task_time"][pilot][method]) for method in study["methods"]]
         for pilot in summary["pilots"]}, output / FIGURE)
    if markdown is not None:
        write_markdown(markdown, f"`{matrix_command(study, summary)}`\n\n" + tables)
    return summary
