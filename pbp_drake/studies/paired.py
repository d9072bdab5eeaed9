"""Two studies of the same seeds, compared trial by trial (`pbp-drake compare A B`), and one
study's methods against one of them (`pbp-drake report DIR --paired-with METHOD`). Per
metric: A's mean, the paired difference B - A with its 95 % t interval, and A's SD and SE;
a difference is *within noise* when its mean is no larger than A's SD, the spread one
trial already carries (docs/tasks/studies.md, "Report and compare"). A metric of a single
pair has no SD, SE or interval: it is shown, not judged.
"""

import dataclasses
import math

import numpy as np

from pbp_drake.scenarios import METHOD_NAMES
from pbp_drake.studies.summary import TRIAL_VALUE, measures_collisions
from pbp_drake.studies.trial_files import read_study

# Metrics that only a task with obstacles measures.
_COLLISION_METRICS = ("collision_ratio", "collision_free")
# (name in the table, how a trial's value is read (None: not recorded), whether both trials
# must have succeeded)
_METRICS = (
    ("success", lambda record: float(bool(record["success"])), False),
    ("intervention_ratio", lambda record: record.get("intervention_ratio"), False),
    ("task_time", lambda record: record.get("task_time"), True),
    ("switches", lambda record: record.get("switches"), False),
    ("collision_ratio", lambda record: record.get("collision_ratio"), False),
    ("collision_free", lambda record: (None if record.get("collision_ratio") is None
                                       else float(record["collision_ratio"] == 0.0)), False),
    ("peak_hand_speed", lambda record: record.get("peak_hand_speed"), False),
    ("peak_command_acceleration", lambda record: record.get("peak_command_acceleration"),
     False),
    # The grasping task's orientation (other tasks' trials have neither).
    ("final_angle_to_target", lambda record: record.get("final_angle_to_target"), False),
    ("peak_command_angular_change", lambda record: record.get("peak_command_angular_change"),
     False),
)


# A difference up to this fraction of the means is floating point's, not a metric's move.
_ROUNDING = 1e-9


# What `report --paired-with` tells of each method against the reference: the outcome, the
# operator's input and the time (the collisions where the task measures them).
PAIRED_METRICS = ("success", "intervention_ratio", "task_time", "collision_ratio")


@dataclasses.dataclass
class PairedRow:
    """One metric of one method over the seeds both studies ran without error."""

    metric: str
    method: str
    pairs: int
    mean_a: float
    mean_b: float
    difference: float  # mean of B - A over the pairs
    low: float  # its 95 % confidence interval
    high: float
    sd_a: float  # A's trial-to-trial standard deviation (NaN for a single pair)
    se_a: float  # A's standard error of the mean (NaN for a single pair)

    @property
    def judged(self):
        """Whether A's SD exists to judge the difference by: two pairs at least (one
        trial's SD is unknown, not 0)."""
        return self.pairs > 1

    @property
    def within_sd(self):
        return self.judged and abs(self.difference) <= self.sd_a + self._rounding

    @property
    def within_se(self):
        return self.judged and abs(self.difference) <= self.se_a + self._rounding

    @property
    def _rounding(self):
        """What floating point alone makes of a difference (the same value computed twice
        may differ in its last bit): never a move, even against an SD of 0."""
        return _ROUNDING * max(abs(self.mean_a), abs(self.mean_b))

    @property
    def moved(self):
        """Whether the difference is larger than A's SD (never for a single pair)."""
        return self.judged and not self.within_sd


def _by_seed(study, records, method):
    """`{seed: record}` of the method's trials on disk that ran without an error."""
    found = {}
    for trial in range(study["trials"]):
        record = records.get((method, trial))
        if record is not None and record.get("error") is None:
            found[study["seed"] + trial] = record
    return found


def _row(metric, method, values_a, values_b):
    a, b = np.array(values_a, float), np.array(values_b, float)
    n = len(a)
    differences = b - a
    difference = float(differences.mean())
    # Deferred: scipy.stats takes about 0.7 s to import, which every command would pay.
    import scipy.stats
    spread = float(differences.std(ddof=1)) if n > 1 else 0.0
    half = float(scipy.stats.t.ppf(0.975, n - 1)) * spread / math.sqrt(n) if n > 1 else math.inf
    sd_a = float(a.std(ddof=1)) if n > 1 else math.nan
    return PairedRow(metric, method, n, float(a.mean()), float(b.mean()), difference,
                     difference - half, difference + half, sd_a, sd_a / math.sqrt(n))


def paired_comparison(folder_a, folder_b, damaged=None, unpaired=None):
    """The `PairedRow`s of two study folders: every metric of every method both ran, over
    the seeds both ran (collisions only where both tasks measure them). Each folder's
    damaged or foreign files (their trials left out) are appended to `damaged` as a
    `trial_files.Damage`, and each method only one folder ran to `unpaired` as `(method,
    "A" or "B")`, one both ran but on no seed both ran without an error as `(method,
    None)`, when they are given."""
    study_a, records_a, damaged_a = read_study(folder_a)
    study_b, records_b, damaged_b = read_study(folder_b)
    if damaged is not None:
        damaged += damaged_a + damaged_b
    if unpaired is not None:
        unpaired += [(method, side) for side, mine, theirs in (
            ("A", study_a["methods"], study_b["methods"]),
            ("B", study_b["methods"], study_a["methods"])) for method in mine
            if method not in theirs]
    collisions = (measures_collisions(study_a, records_a, folder_a)
                  and measures_collisions(study_b, records_b, folder_b))
    rows = []
    for method in [m for m in study_a["methods"] if m in study_b["methods"]]:
        found = _paired_rows(method, _by_seed(study_a, records_a, method),
                             _by_seed(study_b, records_b, method), collisions)
        if not found and unpaired is not None:
            unpaired.append((method, None))
        rows += found
    return rows


def paired_with(folder, reference, metrics, unpaired=None):
    """The `PairedRow`s of one study's every other method (B) against its method `reference`
    (A), for the `metrics` named; each method of no seed both ran without an error is
    appended to `unpaired` when it is given. Raises ValueError when the study did not run
    `reference`."""
    study, records, _ = read_study(folder)
    return paired_rows_with(study, records, reference,
                            measures_collisions(study, records, folder), metrics, unpaired)


def paired_rows_with(study, records, reference, collisions, metrics, unpaired=None):
    """`paired_with` of a study already read (`collisions`: whether its task measures them).
    A metric of `metrics` not in `_METRICS` is read as the records' field of that name (or
    of the name `summary.TRIAL_VALUE` gives it)."""
    if reference not in study["methods"]:
        raise ValueError(f"the study ran {', '.join(study['methods'])}, not {reference}")
    reference_trials = _by_seed(study, records, reference)
    known = {name for name, _, _ in _METRICS}
    fields = tuple(name for name in metrics if name not in known)
    rows = []
    for method in [m for m in study["methods"] if m != reference]:
        found = _paired_rows(method, reference_trials, _by_seed(study, records, method),
                             collisions, fields)
        if not found and unpaired is not None:
            unpaired.append(method)
        rows += found
    return [row for row in rows if row.metric in metrics]


def _record_field(name):
    """A reader of the records' field `name`: its finite number, else None."""
    def read(record):
        value = record.get(name)
        number = isinstance(value, (int, float)) and not isinstance(value, bool)
        return value if number and math.isfinite(value) else None
    return read


def _paired_rows(method, trials_a, trials_b, collisions, fields=()):
    """A row per metric of `method`'s trials B against A (`{seed: record}` each), over the
    seeds both ran; a time only where both succeeded. `fields`: more records' fields."""
    seeds = sorted(set(trials_a) & set(trials_b))
    rows = []
    for metric, read, needs_success in (*_METRICS,
                                        *((name, _record_field(TRIAL_VALUE.get(name, name)),
                                           False) for name in fields)):
        if metric in _COLLISION_METRICS and not collisions:
            continue
        values_a, values_b = [], []
        for seed in seeds:
            record_a, record_b = trials_a[seed], trials_b[seed]
            if needs_success and not (record_a["success"] and record_b["success"]):
                continue
            value_a, value_b = read(record_a), read(record_b)
            if value_a is not None and value_b is not None:
                values_a.append(value_a)
                values_b.append(value_b)
        if values_a:
            rows.append(_row(metric, method, values_a, values_b))
    return rows


def paired_table(rows, name_a, name_b):
    """The rows as a Markdown table, metric by metric."""
    lines = [f"| metric | method | pairs | {name_a} | {name_b} - {name_a} [95 % CI] | "
             f"SD of {name_a} | SE of {name_a} | within noise |",
             "|---|---|---|---|---|---|---|---|"]
    order = [m for m, _, _ in _METRICS]
    for row in sorted(rows, key=lambda row: (order.index(row.metric) if row.metric in order
                                             else len(order))):
        if not row.judged:
            lines.append(f"| {row.metric} | {row.method} | {row.pairs} | {row.mean_a:.4g} | "
                         f"{row.difference:+.3g} | - | - | not judged (one pair) |")
            continue
        verdict = ("yes (within SE too)" if row.within_se else "yes" if row.within_sd
                   else "**no**")
        lines.append(
            f"| {row.metric} | {row.method} | {row.pairs} | {row.mean_a:.4g} | "
            f"{row.difference:+.3g} [{row.low:+.3g}, {row.high:+.3g}] | {row.sd_a:.3g} | "
            f"{row.se_a:.3g} | {verdict} |")
    return "\n".join(lines) + "\n"


def paired_with_markdown(rows, reference, unpaired=()):
    """The rows of `paired_with` as a titled Markdown table, then a line naming the
    `unpaired` methods."""
    name = METHOD_NAMES.get(reference, reference)
    rows = [dataclasses.replace(row, method=METHOD_NAMES.get(row.method, row.method))
            for row in rows]
    left_out = "".join(f"{METHOD_NAMES.get(method, method)}: no seed it and {name} both ran "
                       "without an error, not compared.\n" for method in unpaired)
    return (f"Each method against {name}, paired by seed (the method minus {name}, with "
            f"the 95 % interval of the difference; within noise: no larger than {name}'s "
            "trial-to-trial SD).\n\n" + paired_table(rows, name, "method")
            + ("\n" + left_out if left_out else ""))
