"""95 % confidence intervals of a method comparison's results, from its summary alone: the
success rate's (Wilson's score interval) and the means' (Student's t, from the mean and
population standard deviation over the trials that ran, cut to the range the metric can
take), as a table below the results table (`report.results_table`)."""

import math

from pbp_drake.scenarios import METHOD_NAMES

# The two-sided 95 % normal quantile of Wilson's interval.
Z_95 = 1.959963984540054
RATIO, TIME, COSINE = (0.0, 1.0), (0.0, math.inf), (-1.0, 1.0)  # metrics' ranges
# The metrics whose mean gets an interval: (summary entry, column, digits, range); first
# the interaction metrics of `pbp_drake.core.interaction_metrics`.
INTERACTION_MEANS = (("input_integral", "input (m)", 3, TIME),
                     ("turn_input_integral", "turning input (rad)", 2, TIME),
                     ("idle_ratio", "idle ratio", 3, RATIO),
                     ("agreement", "agreement", 3, COSINE),
                     ("prediction_accuracy", "prediction accuracy", 3, RATIO),
                     ("time_to_prediction", "time to prediction (s)", 2, TIME))
MEAN_METRICS = (("intervention_ratio", "intervention ratio", 3, RATIO),
                ("task_time", "task time (s)", 1, TIME),
                ("collision_ratio", "collision ratio", 3, RATIO),
                ("posterior_clipped_ratio", "posterior at its clip", 3, RATIO),
                *INTERACTION_MEANS)


def wilson_interval(successes, trials, z=Z_95):
    """`(low, high)` of Wilson's score interval of a success rate, or None without trials."""
    if trials <= 0:
        return None
    rate = successes / trials
    scale = 1.0 + z * z / trials
    centre = (rate + z * z / (2 * trials)) / scale
    half = z * math.sqrt(rate * (1 - rate) / trials + z * z / (4 * trials * trials)) / scale
    return max(0.0, centre - half), min(1.0, centre + half)


def mean_interval(mean, population_std, count, within=(-math.inf, math.inf)):
    """`(low, high)` of the t interval of a mean of `count` values, from their mean and
    population standard deviation, cut to `within`; None for fewer than two or no mean."""
    if mean is None or population_std is None or count < 2:
        return None
    # Deferred: scipy.stats takes about 0.7 s to import, which every command would pay.
    import scipy.stats
    sample_std = population_std * math.sqrt(count / (count - 1))
    half = float(scipy.stats.t.ppf(0.975, count - 1)) * sample_std / math.sqrt(count)
    return max(within[0], mean - half), min(within[1], mean + half)


def _interval_cell(interval, digits, percent=False):
    if interval is None:
        return "-"
    low, high = (100 * value for value in interval) if percent else interval
    unit = " %" if percent else ""
    return f"[{low:.{digits}f}, {high:.{digits}f}]{unit}"


def confidence_table(summary):
    """The Markdown lines of the 95 % intervals, one row per method: the success rate over
    the trials on disk, and the mean of each of `MEAN_METRICS` the summary holds over the
    trials that ran (those with a value, for an entry that counts them)."""
    methods = summary["methods"]
    metrics = [metric for metric in MEAN_METRICS
               if any(metric[0] in entry for entry in methods.values())]
    columns = ["method", "success", *(column for _, column, _, _ in metrics)]
    lines = ["95 % confidence intervals: the success rate's (Wilson score) and each mean's "
             "(Student's t over the trials that ran, within the metric's range).", "",
             "| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for method, entry in methods.items():
        rate = entry["success_rate"]
        success = (None if rate is None else
                   wilson_interval(round(rate * entry["trials"]), entry["trials"]))
        ran = entry["trials"] - entry["errors"]
        cells = [METHOD_NAMES.get(method, method), _interval_cell(success, 0, percent=True)]
        for key, _, digits, within in metrics:
            value = entry.get(key)
            cells.append("-" if value is None else _interval_cell(mean_interval(
                value["mean"], value["std"], value.get("count", ran), within), digits))
        lines.append("| " + " | ".join(cells) + " |")
    return lines
