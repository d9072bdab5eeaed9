"""Figures of the method comparison study in the paper's form (Fig. 7): (a) box plots of the
intervention ratio, (b) of the task time, (c) the histogram of per-trial collision ratios.
They read trial records (dicts from the trial files), never a simulation."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

METHOD_LABELS = {"pbp_alternated": "PBP-Alt", "pbp_continuous": "PBP-Cont",
                 "teleop": "Teleop", "pbp_no_user": "PBP-NoUser", "fixed_alpha": "Fixed alpha"}
METHOD_COLOURS = {"pbp_alternated": "tab:orange", "pbp_continuous": "tab:blue",
                  "teleop": "tab:green", "pbp_no_user": "tab:gray", "fixed_alpha": "tab:purple"}


def _label(method, rows=None):
    label = METHOD_LABELS.get(method, method)
    if rows:
        rate = np.mean([bool(r["success"]) for r in rows])
        label += f"\n{100 * rate:.0f} % success"
    return label


def _values(records, method, field):
    return [r[field] for r in records if r["method"] == method and r.get("error") is None
            and r.get(field) is not None and np.isfinite(r[field])]


def _box_plot(records, methods, field, ylabel, title, path, ylim=None):
    figure, axis = plt.subplots(figsize=(1.6 + 1.3 * len(methods), 3.6))
    data = [_values(records, method, field) for method in methods]
    labels = [_label(m, [r for r in records if r["method"] == m]) for m in methods]
    # A method with no finished trial gets an empty box (matplotlib needs one value: NaN).
    boxes = axis.boxplot([d if d else [np.nan] for d in data], patch_artist=True)
    for patch, method in zip(boxes["boxes"], methods):
        patch.set_facecolor(METHOD_COLOURS.get(method, "0.8"))
        patch.set_alpha(0.6)
    for index, values in enumerate(data, start=1):
        jitter = np.linspace(-0.12, 0.12, len(values)) if len(values) > 1 else np.zeros(
            len(values))
        axis.plot(index + jitter, values, "k.", ms=3, alpha=0.6)
    axis.set_xticks(range(1, len(methods) + 1), labels, fontsize=8)
    axis.set_ylabel(ylabel)
    axis.set_title(title)
    axis.grid(axis="y", alpha=0.3)
    if ylim is not None:
        axis.set_ylim(*ylim)
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)


def plot_intervention(records, methods, path):
    """Fig. 7a: the intervention ratio per method (box plots, one dot per trial)."""
    _box_plot(records, methods, "intervention_ratio", "intervention ratio",
              "(a) intervention ratio", path, ylim=(-0.02, 1.05))


def plot_task_time(records, methods, path):
    """Fig. 7b: the task time per method (a failed trial counts with the time limit)."""
    _box_plot(records, methods, "task_time", "task time (s)", "(b) task time", path)


def plot_collision_histogram(summary, path):
    """Fig. 7c: how many trials of each method had each collision ratio, in the summary's
    fixed bins (all zeros, as in tasks without obstacles, make one bar per method)."""
    edges = np.asarray(summary["collision_histogram_edges"], float)
    methods = list(summary["methods"])
    figure, axis = plt.subplots(figsize=(7, 3.6))
    width = np.diff(edges) / (len(methods) + 1)
    for index, method in enumerate(methods):
        entry = summary["methods"][method]["collision_ratio"]
        mean = entry["mean"]
        label = METHOD_LABELS.get(method, method) + (
            f" (mean {mean:.3f})" if mean is not None else " (no trials)")
        axis.bar(edges[:-1] + (index + 0.5) * width, entry["histogram"], width=width,
                 align="edge", color=METHOD_COLOURS.get(method), label=label, alpha=0.85)
    axis.set_xlim(edges[0], edges[-1])
    axis.set_xlabel("collision ratio (ticks in collision / ticks)")
    axis.set_ylabel("trials")
    axis.set_title("(c) collision ratios")
    axis.yaxis.get_major_locator().set_params(integer=True)
    axis.legend(fontsize=8)
    axis.grid(axis="y", alpha=0.3)
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)

