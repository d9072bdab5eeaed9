"""The bench's figures: the control rate reached (1 / step time) versus K, and the closed
loop's real-time factor versus K."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from pbp_drake_bench.cases import BASIS  # noqa: E402


def plot_control_rate(rows, path):
    """Control rate reached (1 / step time) versus K, for D = 3 (or the first D measured)."""
    rows = [row for row in rows if not row.get("pose")]  # the position bank's rows
    dimensions = sorted({row["D"] for row in rows})
    dimension = 3 if 3 in dimensions else dimensions[0]
    figure, axes = plt.subplots(figsize=(7.5, 5))
    series = [("leaf_us", "distinct", "bank in LeafSystem, distinct weights", "C0", "-o"),
              ("leaf_us", "shared", "bank in LeafSystem, one shared demo", "C1", "-o"),
              ("bank_math_us", "distinct", "bank math, distinct weights", "C0", ":."),
              ("bank_math_us", "shared", "bank math, one shared demo", "C1", ":."),
              ("mp_stacked_us", "distinct", "movement_primitives, K*D stacked", "C2", "--s"),
              ("pydmps_per_goal_us", "distinct", "pydmps, one object per goal", "C3", "--^"),
              ("mp_per_goal_us", "distinct", "movement_primitives, one per goal", "C4", "--v")]
    for key, weights, label, color, style in series:
        points = [(row["K"], 1e6 / row[key]) for row in rows
                  if row["D"] == dimension and row["weights"] == weights and row.get(key)]
        if points:
            k, rate = zip(*points)
            axes.plot(k, rate, style, color=color, label=label)
    axes.axhline(1000, color="grey", lw=0.8, ls="--")
    axes.axhline(30, color="grey", lw=0.8, ls=":")
    axes.text(1, 1100, "1 kHz", color="grey")
    axes.text(1, 33, "30 Hz (paper)", color="grey")
    axes.plot([100], [30], "k*", ms=12, label="paper, Fig. 6c: 100 DMPs at 30 Hz")
    return _save(figure, axes, path, "goals K (one DMP each)",
                 "control rate reached (Hz) = 1 / step time",
                 f"DMP bank step, D = {dimension}, N = {BASIS} basis functions", "lower left")


def _save(figure, axes, path, xlabel, ylabel, title, legend_at):
    """Log-log axes with their labels, grid and legend, saved to `path` (returned)."""
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_xlabel(xlabel)
    axes.set_ylabel(ylabel)
    axes.set_title(title)
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8, loc=legend_at)
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return path


def plot_scaling(closed_loop, path):
    """The closed loop's real-time factor versus K (log x): reach and grasp, headless
    (median) and with Meshcat and a client, on the scenario files' robots; a line at 1x."""
    figure, axes = plt.subplots(figsize=(7.5, 5))
    series = [("reach", False, "reaching, headless", "C0", "-o"),
              ("reach", True, "reaching, Meshcat + client", "C0", "--s"),
              ("grasp", False, "grasping (six-DoF), headless", "C1", "-o"),
              ("grasp", True, "grasping (six-DoF), Meshcat + client", "C1", "--s")]
    for task, meshcat, label, color, style in series:
        points = sorted((run["goals"], run["realtime_factor"]) for run in closed_loop
                        if run.get("task", "reach") == task and run["meshcat"] == meshcat
                        and run.get("shipped_robot", True))
        if points:
            k, factor = zip(*points)
            axes.plot(k, factor, style, color=color, label=label)
    axes.axhline(1.0, color="grey", lw=0.8, ls="--")
    axes.text(0.99, 1.03, "real time", color="grey", ha="right", va="bottom",
              transform=axes.get_yaxis_transform())
    return _save(figure, axes, path, "goals K", "real-time factor (simulated s / wall s)",
                 "Closed loop, HSR tasks (virtual participant, PBP-Alt)", "best")
