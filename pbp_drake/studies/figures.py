"""The paper's figures, drawn with matplotlib (headless) from trial records or summaries:
the 2-D studies' Fig. 2 (the alpha study) and Fig. 4 (Alt vs Cont), the method
comparison's Fig. 7 (box plots of (a) the intervention ratio and (b) the task time, (c)
the histogram of collision ratios) and a matrix of methods and pilots in one figure.

matplotlib is imported where a figure is drawn, so that a command that draws none (a run,
a trial) starts without loading its figures and axes."""

import numpy as np

from pbp_drake.core.methods import method_colour, methods_of
from pbp_drake.scenarios import METHOD_NAMES
from pbp_drake.studies.atomic_files import save_figure


def new_figure(*grid, figsize, **options):
    """A figure and its axes (`Figure.subplots`) made without pyplot, which would choose a
    backend: a notebook that draws these keeps its own (its inline figures)."""
    from matplotlib.figure import Figure
    figure = Figure(figsize=figsize)
    return figure, figure.subplots(*grid, **options)


# ---------------------------------------------------------------------------------------------
# The method comparison (Fig. 7)


def _save(figure, path, **options):
    figure.tight_layout()
    save_figure(figure, path, **options)


def _label(method, rows=None):
    label = METHOD_NAMES.get(method, method)
    if rows:
        rate = np.mean([bool(r["success"]) for r in rows])
        label += f"\n{100 * rate:.0f} % success"
    return label


def _label_axes(axes, xlabel, ylabel, title, **legend):
    axes.set_xlabel(xlabel)
    axes.set_ylabel(ylabel)
    axes.set_title(title)
    axes.legend(**legend)


def _values(records, method, field):
    return [r[field] for r in records if r["method"] == method and r.get("error") is None
            and r.get(field) is not None and np.isfinite(r[field])]


def _box_plot(records, methods, field, ylabel, title, path, ylim=None):
    figure, axis = new_figure(figsize=(1.6 + 1.3 * len(methods), 3.6))
    data = [_values(records, method, field) for method in methods]
    labels = [_label(m, [r for r in records if r["method"] == m]) for m in methods]
    # A method with no finished trial gets an empty box (matplotlib needs one value: NaN).
    boxes = axis.boxplot([d if d else [np.nan] for d in data], patch_artist=True)
    for patch, method in zip(boxes["boxes"], methods):
        patch.set_facecolor(method_colour(method, "0.8"))
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
    _save(figure, path, dpi=120)


def plot_intervention(records, methods, path):
    """Fig. 7a: the intervention ratio per method (box plots, one dot per trial)."""
    _box_plot(records, methods, "intervention_ratio", "intervention ratio",
              "(a) intervention ratio", path, ylim=(-0.02, 1.05))


def plot_task_time(records, methods, path):
    """Fig. 7b: the task time per method (a failed trial counts with the time limit)."""
    _box_plot(records, methods, "task_time", "task time (s)", "(b) task time", path)


def plot_collision_histogram(summary, path):
    """Fig. 7c: each method's trials per bin of collision ratio (the summary's histogram)."""
    edges = np.asarray(summary["collision_histogram_edges"], float)
    methods = list(summary["methods"])
    figure, axis = new_figure(figsize=(7, 3.6))
    width = np.diff(edges) / (len(methods) + 1)
    for index, method in enumerate(methods):
        entry = summary["methods"][method]["collision_ratio"]
        mean = entry["mean"]
        label = METHOD_NAMES.get(method, method) + (
            f" (mean {mean:.3f})" if mean is not None else " (no trials)")
        axis.bar(edges[:-1] + (index + 0.5) * width, entry["histogram"], width=width,
                 align="edge", color=method_colour(method), label=label, alpha=0.85)
    axis.set_xlim(edges[0], edges[-1])
    _label_axes(axis, "collision ratio (ticks in collision / ticks)", "trials",
                "(c) collision ratios", fontsize=8)
    axis.yaxis.get_major_locator().set_params(integer=True)
    axis.grid(axis="y", alpha=0.3)
    _save(figure, path, dpi=120)


def _error_bar(axis, x, interval, **style):
    mean, low, high = interval
    if mean is None:
        return
    error = None if low is None else [[mean - low], [high - mean]]
    axis.errorbar([x], [mean], yerr=error, capsize=3, **style)


def plot_pilot_panels(panels, path):
    """A panel per pilot: each method's mean intervention ratio (circles, left axis) and task
    time (squares, right axis) with their 95 % intervals. `panels`: `{pilot: [(method,
    (mean, low, high) of the ratio, the same of the time)]}` (low, high None: no interval)."""
    count = len(panels)
    figure, axes = new_figure(1, count, figsize=(1.2 + 3.4 * count, 3.8), squeeze=False)
    times = [t[0] for rows in panels.values() for _, _, t in rows if t[0] is not None]
    highs = [t[2] for rows in panels.values() for _, _, t in rows if t[2] is not None]
    time_top = 1.1 * max(times + highs) if times else 1.0
    for axis, (pilot, rows) in zip(axes[0], panels.items()):
        time_axis = axis.twinx()
        for index, (method, ratio, time) in enumerate(rows):
            colour = method_colour(method, "0.4")
            _error_bar(axis, index - 0.12, ratio, fmt="o", color=colour)
            _error_bar(time_axis, index + 0.12, time, fmt="s", color=colour, mfc="white")
        axis.set_xticks(range(len(rows)), [_label(method) for method, _, _ in rows],
                        rotation=30, ha="right", fontsize=8)
        axis.set_xlim(-0.5, len(rows) - 0.5)
        axis.set_ylim(-0.02, 1.05)
        axis.set_ylabel("intervention ratio (circles)")
        time_axis.set_ylim(0, time_top)
        time_axis.set_ylabel("task time, s (squares)")
        axis.set_title(f"pilot: {pilot}")
        axis.grid(axis="y", alpha=0.3)
    figure.suptitle("Every method under every pilot: means and 95 % intervals", fontsize=10)
    _save(figure, path, dpi=110)


# ---------------------------------------------------------------------------------------------
# The 2-D studies (Fig. 2 and 4)

SCENE_COLOURS = ["tab:red", "tab:purple", "tab:brown", "tab:olive"]


def _draw_obstacles(axes, obstacles, colour, label=None):
    from matplotlib.patches import Circle
    for index, obstacle in enumerate(obstacles):
        axes.add_patch(Circle(obstacle.center, obstacle.radius, color=colour, alpha=0.3,
                              label=label if index == 0 else None))


def _draw_task(axes, resolved):
    demo = resolved.demonstration[1]
    axes.plot(demo[:, 0], demo[:, 1], "k--", lw=1.2, label="demonstration")
    start, goal = resolved.start, resolved.goals[0]
    axes.plot(*start, "ko", ms=5)
    axes.plot(*goal, "k*", ms=10)
    axes.set_aspect("equal")
    axes.set_xlabel("x")
    axes.set_ylabel("y")


SPEED_STYLES = ["-", "--", ":", "-."]


def _trajectory_speed(summary, resolved):
    """The speed key panel (d) draws: the operator's own speed when swept, else the first."""
    own = getattr(resolved.scenario.operator, "speed", None)
    keys = list(summary["scenes"][0]["by_operator_speed"])
    speeds = summary["operator_speeds"]
    return keys[speeds.index(own)] if own in speeds else keys[0]


def _outcome_text(outcome):
    return (f"coll. {outcome['collision_ratio']:.3f}, "
            f"ends {outcome['final_distance']:.2f} from goal")


def plot_alpha_study(resolved, study, summary, trajectories, path):
    """Fig. 2: (a) the scenes, (b) collision ratio and (c) final distance to the goal
    against alpha, per scene and operator speed, (d) trajectories under explicit
    arbitration, then one panel of PBP trajectories per operator speed."""
    # Trajectories are keyed (scene name, speed key as in the summary, alpha or method).
    speeds = list(summary["scenes"][0]["by_operator_speed"])
    columns = max(3, 1 + len(speeds))
    figure, axes = new_figure(2, columns, figsize=(5.2 * columns, 9), squeeze=False)
    scenes_axes, ratio_axes, distance_axes = axes[0, :3]
    for spare in axes[0, 3:]:
        spare.axis("off")
    alpha_axes, pbp_axes = axes[1, 0], axes[1, 1:1 + len(speeds)]
    for spare in axes[1, 1 + len(speeds):]:
        spare.axis("off")

    _draw_task(scenes_axes, resolved)
    _draw_obstacles(scenes_axes, study.demonstration_obstacles, "0.5", "during demonstration")
    for index, scene in enumerate(study.scenes):
        _draw_obstacles(scenes_axes, scene.obstacles, SCENE_COLOURS[index % 4], scene.name)
    scenes_axes.set_title("(a) demonstration and the test scenes")
    scenes_axes.legend(fontsize=7, loc="lower center")

    for index, scene in enumerate(summary["scenes"]):
        colour = SCENE_COLOURS[index % 4]
        for speed_index, (key, results) in enumerate(scene["by_operator_speed"].items()):
            style = SPEED_STYLES[speed_index % len(SPEED_STYLES)]
            alphas = [float(a) for a in results["fixed_alpha"]]
            outcomes = list(results["fixed_alpha"].values())
            label = f"{scene['name']}, speed {key}"
            ratio_axes.plot(alphas, [o["collision_ratio"] for o in outcomes], "o" + style,
                            color=colour, ms=3, label=label + (
                                f" (ideal alpha {results['ideal_alpha']:g})"
                                if results["ideal_alpha"] is not None else ""))
            distance_axes.plot(alphas, [o["final_distance"] for o in outcomes], "o" + style,
                               color=colour, ms=3, label=label)
    distance_axes.axhline(summary["goal_tolerance"], color="k", lw=0.8,
                          label=f"goal tolerance {summary['goal_tolerance']:g}")
    _label_axes(ratio_axes, "alpha (1: robot only)", "ratio of states in collision",
                "(b) explicit arbitration: collisions against alpha", fontsize=6)
    _label_axes(distance_axes, "alpha (1: robot only)", "final distance to the goal",
                "(c) explicit arbitration: final distance against alpha", fontsize=6)

    import matplotlib
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    colour_map = matplotlib.colormaps["viridis"]
    drawn_speed = _trajectory_speed(summary, resolved)
    for index, scene in enumerate(study.scenes):
        colour = SCENE_COLOURS[index % 4]
        # The PBP panels' legends name the runs; their obstacles need no entry.
        _draw_obstacles(alpha_axes, scene.obstacles, colour, scene.name)
        for target in pbp_axes:
            _draw_obstacles(target, scene.obstacles, colour)
        for alpha in study.alphas:
            positions = trajectories[(scene.name, drawn_speed, alpha)]
            alpha_axes.plot(positions[:, 0], positions[:, 1], color=colour_map(alpha), lw=1,
                            alpha=0.8)
        results = summary["scenes"][index]["by_operator_speed"]
        for speed, target in zip(speeds, pbp_axes):
            outcomes = results[speed]
            for method, style in zip(methods_of("pbp"), ("-", "--")):
                positions = trajectories[(scene.name, speed, method)]
                target.plot(positions[:, 0], positions[:, 1], style, color=colour, lw=1.5,
                            label=f"{scene.name} {METHOD_NAMES[method]}: "
                                  f"{_outcome_text(outcomes[method])}")
    for target in (alpha_axes, *pbp_axes):
        _draw_task(target, resolved)
    mappable = ScalarMappable(cmap=colour_map, norm=Normalize(0, 1))
    figure.colorbar(mappable, ax=alpha_axes, label="alpha")
    alpha_axes.set_title(f"(d) explicit arbitration, every alpha\n"
                         f"(operator speed {drawn_speed})")
    for letter, speed, target in zip("efghij", speeds, pbp_axes):
        target.set_title(f"({letter}) PBP (no alpha), operator speed {speed}")
        target.legend(fontsize=6, loc="upper center", bbox_to_anchor=(0.5, -0.12))
    _save(figure, path, dpi=110, bbox_inches="tight")  # the legends under the PBP panels


def plot_alt_vs_cont(resolved, summary, path):
    """Fig. 4: the two modes' paths, their y against the phase, and the input."""
    figure, (path_axes, phase_axes, input_axes) = new_figure(1, 3, figsize=(14, 4))
    for method, mode in summary["modes"].items():
        label, colour = METHOD_NAMES[method], method_colour(method)
        positions = np.asarray(mode["positions"])
        phase = np.asarray(mode["phase"])
        active = np.asarray(mode["operator_active"], bool)
        path_axes.plot(positions[:, 0], positions[:, 1], color=colour,
                       label=f"{label} (final error {mode['final_error'] * 100:.2f} cm)")
        phase_axes.plot(phase, positions[:, 1], color=colour, label=label)
        phase_axes.plot(phase[active], positions[active, 1], ".", color=colour, ms=3)
        input_axes.plot(mode["times"], phase, color=colour, label=label)
    goal = summary["goal"]
    path_axes.plot(*goal[:2], "k*", ms=10)
    _label_axes(path_axes, "x", "y", "paths under the same input", fontsize=8)
    _label_axes(phase_axes, "phase (t / tau while running)", "y",
                "y against phase (dots: operator acting)", fontsize=8)
    any_mode = next(iter(summary["modes"].values()))
    input_axes.fill_between(any_mode["times"], 0, np.max([m["phase"] for m in
                            summary["modes"].values()]), where=np.asarray(
                            any_mode["operator_active"], bool), color="0.85", label="input on")
    _label_axes(input_axes, "time (s)", "phase", "phase against time", fontsize=8)
    _save(figure, path, dpi=110)
