"""The K sweep's figure and table (docs/results/many-goals.md): each method's success,
intervention ratio and task time over teleop's against the number of goals K (PBP-Alt
following one goal, the paper's, and with goal groups under each estimator; the other
methods with groups and the intent filter where they follow DMPs), from the summaries of
the catalogue's many-goals studies. `make results` writes both after those studies; alone:
`python -m pbp_drake_bench.many_goals_figure [--outputs DIR] [--figure PNG] [--table MD]`.
"""

import argparse
import json
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

#: The figure's and the table's file names beside the generated tables.
FIGURE = "many_goals.png"
TABLE = "many_goals_sweep.md"
GOAL_COUNTS = (4, 100, 1000)
ESTIMATORS = ("angle", "nearest", "bayesian", "maxent_command", "intent_filter")
#: The other methods, each K's study of them (goal groups and the intent filter, which HOP's
#: methods, with no DMPs, do not use): method -> the line's label.
OTHER_METHODS = {"pbp_continuous": "PBP-Cont, groups, intent_filter", "hop": "HOP",
                 "predict_then_assist": "predict-then-assist",
                 "confidence_alpha": "confidence_alpha, groups, intent_filter"}


def study_name(goals, estimator=None):
    """The catalogue's study of K `goals`: following one goal (`estimator` None, with
    teleop), or with goal groups under `estimator`."""
    if estimator is None:
        return f"hsr_reach_goals_{goals}"
    return f"hsr_reach_goals_{goals}_groups" + ("" if estimator == "angle" else f"_{estimator}")


def methods_study_name(goals):
    """The catalogue's study of the `OTHER_METHODS` at K `goals`."""
    return f"hsr_reach_goals_{goals}_methods"


def _method(outputs, name, method):
    path = pathlib.Path(outputs) / name / "summary.json"
    if not path.is_file():
        return None
    return json.loads(path.read_text())["methods"].get(method)


def sweep(outputs):
    """{label: [(K, intervention ratio, task time / teleop's, success rate)]} of every line
    that has its studies on disk (teleop's own line at time ratio 1)."""
    teleops = {goals: _method(outputs, study_name(goals), "teleop") for goals in GOAL_COUNTS}
    lines = {}
    # label -> (its study at K, the method read there)
    for label, (name, method) in {
            "PBP-Alt, one goal (angle)": (study_name, "pbp_alternated"),
            **{f"PBP-Alt, groups, {e}": ((lambda goals, e=e: study_name(goals, e)),
                                         "pbp_alternated") for e in ESTIMATORS},
            **{label: (methods_study_name, method)
               for method, label in OTHER_METHODS.items()}}.items():
        points = []
        for goals, teleop in teleops.items():
            result = _method(outputs, name(goals), method)
            if teleop and result:
                points.append((goals, result["intervention_ratio"]["mean"],
                               result["task_time"]["mean"] / teleop["task_time"]["mean"],
                               result["success_rate"]))
        if points:
            lines[label] = points
    teleop = [(goals, method["intervention_ratio"]["mean"], 1.0, method["success_rate"])
              for goals, method in teleops.items() if method]
    if teleop:
        lines["teleop"] = teleop
    return lines


def plot_many_goals(lines, figure):
    """Draws `lines` (a `sweep`) into `figure`; returns False (and draws nothing) when it
    is empty (no study on disk)."""
    if not lines:
        return False
    fig, (intervention, time) = plt.subplots(1, 2, figsize=(10, 5))
    # tab20's dark shades, then its light ones: a colour of its own for each line; teleop's
    # black.
    colours = plt.get_cmap("tab20").colors[::2] + plt.get_cmap("tab20").colors[1::2]
    for index, (label, points) in enumerate(lines.items()):
        goals, ratio, time_ratio, _ = zip(*points)
        colour = "black" if label == "teleop" else colours[index % len(colours)]
        style = dict(marker="o", label=label, color=colour,
                     linestyle="--" if "teleop" in label or "one goal" in label else "-")
        intervention.plot(goals, ratio, **style)
        time.plot(goals, time_ratio, **style)
    for axes, title in ((intervention, "intervention ratio"),
                        (time, "task time / teleop's")):
        axes.set_xscale("log")
        axes.set_xticks(GOAL_COUNTS, [f"{k:,}" for k in GOAL_COUNTS])
        axes.set_xlabel("goals K")
        axes.set_title(title)
        axes.grid(alpha=0.3)
    intervention.set_ylim(0.0, 1.05)
    fig.legend(*intervention.get_legend_handles_labels(), loc="lower center", ncol=3,
               fontsize=8)
    fig.suptitle("Reaching with K goals on a grid, evaluation seeds (means over 30 trials)")
    fig.tight_layout(rect=(0.0, 0.17, 1.0, 1.0))
    pathlib.Path(figure).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(figure, dpi=110)
    plt.close(fig)
    return True


def write_sweep_table(lines, table):
    """`lines` (a `sweep`) as a Markdown table into `table` (the command that made it
    first); returns False (and writes nothing) when it is empty (no study on disk)."""
    if not lines:
        return False
    text = ["<!-- written by python -m pbp_drake_bench.many_goals_figure (make results) "
            "from the summaries of the many-goals studies -->", "",
            "| success, intervention ratio, task time / teleop's | "
            + " | ".join(f"K = {k:,}" for k in GOAL_COUNTS) + " |",
            "|---|" + "---|" * len(GOAL_COUNTS)]
    for label, points in lines.items():
        by_goals = {point[0]: point for point in points}
        cells = [(f"{100 * p[3]:.0f} %, {p[1]:.3f}, {p[2]:.2f}x" if (p := by_goals.get(k))
                  else "-") for k in GOAL_COUNTS]
        text.append(f"| {label} | " + " | ".join(cells) + " |")
    pathlib.Path(table).parent.mkdir(parents=True, exist_ok=True)
    pathlib.Path(table).write_text("\n".join(text) + "\n")
    return True


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m pbp_drake_bench.many_goals_figure",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--outputs", default="outputs/results",
                        help="the catalogue's study folders (default outputs/results)")
    parser.add_argument("--figure", default=f"docs/results/generated/{FIGURE}",
                        help=f"the figure to write (default docs/results/generated/{FIGURE})")
    parser.add_argument("--table", default=f"docs/results/generated/{TABLE}",
                        help=f"the table to write (default docs/results/generated/{TABLE})")
    args = parser.parse_args(argv)
    lines = sweep(args.outputs)
    if not plot_many_goals(lines, args.figure):
        parser.error(f"no many-goals study under {args.outputs} (make results runs them)")
    write_sweep_table(lines, args.table)
    print(f"  wrote {args.figure} and {args.table}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
