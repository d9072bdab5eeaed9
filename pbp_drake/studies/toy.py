"""The paper's 2-D experiments as studies: the alpha study (Fig. 2) and Alt vs Cont (Fig. 4).

Each study simulates its scenario's variants through the one builder, writes
`summary.json` and the paper's figure into an output folder, and returns the summary.
"""

import dataclasses
import json
import math
import pathlib

import numpy as np

from pbp_drake.core.toy_scene import collision_ratio
from pbp_drake.scenarios import AlphaStudy, AltVsCont, resolve
from pbp_drake.builder.run import simulate
from pbp_drake.studies.figures import plot_alpha_study, plot_alt_vs_cont
from pbp_drake.studies.folders import folder_kind
from pbp_drake.studies.trial_files import StudyFolderError
from pbp_drake.studies.summary import collision_free, ideal_alpha


# The figure each 2-D study writes beside its summary.json.
TOY_FIGURES = {"alpha_study": "fig2_alpha_study.png", "alt_vs_cont": "fig4_alt_vs_cont.png"}


def run_study(scenario_file, output_dir):
    """Runs the study a scenario file describes; returns its summary. Raises
    StudyFolderError when `output_dir` holds a study of another kind (a method comparison,
    or the other 2-D study), whose summary.json it would overwrite."""
    output_dir = pathlib.Path(output_dir)
    if isinstance(scenario_file.study, AlphaStudy):
        kind, run = "alpha_study", run_alpha_study
    elif isinstance(scenario_file.study, AltVsCont):
        kind, run = "alt_vs_cont", run_alt_vs_cont
    else:
        raise ValueError("this scenario file has no `study:` section to run")
    held = folder_kind(output_dir)
    if held is not None and held != kind:
        raise StudyFolderError(f"{output_dir} holds a study of kind {held!r}, not a 2-D "
                               f"{kind}: choose another --output folder")
    output_dir.mkdir(parents=True, exist_ok=True)
    return run(scenario_file.resolved, scenario_file.study, output_dir)


def scene_scenario(scenario, scene):
    """The scenario with a scene's obstacles."""
    return dataclasses.replace(scenario, name=f"{scenario.name}/{scene.name}",
                               obstacles=list(scene.obstacles))


def _ratio(trajectory, obstacles):
    return collision_ratio(trajectory.positions, [o.center for o in obstacles],
                           [o.radius for o in obstacles])


def run_alpha_study(resolved, study, output_dir):
    """Explicit arbitration over alpha (P: the demonstration, open loop) against PBP-Alt and
    PBP-Cont (P: a DMP learned from it), the same virtual operator in every run."""
    scenario = resolved.scenario
    scenes = []
    trajectories = {}
    for scene in study.scenes:
        # Each scene's obstacles are resolved once; the methods share its DMPs.
        base = resolve(scene_scenario(scenario, scene))
        ratios = {}
        for alpha in study.alphas:
            run = simulate(base.with_method(f"fixed_alpha={alpha!r}"))
            ratios[f"{alpha:.2f}"] = _ratio(run, scene.obstacles)
            trajectories[(scene.name, alpha)] = run.positions
        pbp = {}
        for method in ("pbp_alternated", "pbp_continuous"):
            run = simulate(base.with_method(method))
            pbp[method] = _ratio(run, scene.obstacles)
            trajectories[(scene.name, method)] = run.positions
        # The highest alpha that still lets the operator pass the obstacles untouched.
        ideal = ideal_alpha([(alpha, ratios[f"{alpha:.2f}"]) for alpha in study.alphas],
                            collision_free)
        scenes.append({
            "name": scene.name,
            "obstacles": [dataclasses.asdict(o) for o in scene.obstacles],
            "collision_ratio_by_alpha": ratios,
            "ideal_alpha": ideal,
            "pbp_alternated_collision_ratio": pbp["pbp_alternated"],
            "pbp_continuous_collision_ratio": pbp["pbp_continuous"],
        })
    summary = {"study": "alpha_study", "scenario": scenario.name, "alphas": study.alphas,
               "scenes": scenes}
    _write_json(output_dir / "summary.json", summary)
    plot_alpha_study(resolved, study, summary, trajectories, output_dir / "fig2_alpha_study.png")
    return summary


def phase_progress(phase, alpha_x):
    """The phase as progress `phi = -ln(x) / alpha_x` (`t / tau` while never locked), the
    increasing phase axis of the paper's Fig. 4."""
    return -np.log(np.maximum(phase, 1e-300)) / alpha_x


def run_alt_vs_cont(resolved, study, output_dir):
    """The same DMP under the same open-loop input in continuous and alternated mode."""
    scenario = resolved.scenario
    goal = resolved.goals[0]
    modes = {}
    runs = {}
    for method in ("pbp_continuous", "pbp_alternated"):
        run = simulate(resolved.with_method(method))
        runs[method] = run
        progress = phase_progress(run.phase[:, 0], scenario.dmp.alpha_x)
        # progress[k] is the phase with which tick k steps; tick k changed it iff
        # progress[k + 1] != progress[k].
        change = np.diff(progress)
        acting = run.operator_active[:-1]
        last_input = np.flatnonzero(run.operator_active)
        modes[method] = {
            "times": run.times.tolist(),
            "phase": progress.tolist(),
            "operator_active": run.operator_active.astype(int).tolist(),
            "positions": run.positions.tolist(),
            "final_error": float(np.linalg.norm(run.positions[-1] - goal)),
            "input_stopped_at": float(run.times[last_input[-1] + 1]) if last_input.size else 0.0,
            "phase_constant_while_operator_acts": bool(np.all(change[acting] == 0.0)),
            "phase_strictly_increasing": bool(np.all(change > 0.0)),
        }
    summary = {
        "study": "alt_vs_cont",
        "scenario": scenario.name,
        "goal": goal.tolist(),
        "goal_tolerance": study.goal_tolerance,
        "modes": modes,
        "both_reach_goal": all(m["final_error"] <= study.goal_tolerance for m in modes.values()),
    }
    _write_json(output_dir / "summary.json", summary)
    plot_alt_vs_cont(resolved, summary, output_dir / "fig4_alt_vs_cont.png")
    return summary


def _write_json(path, data):
    def clean(value):
        if isinstance(value, float) and not math.isfinite(value):
            return None
        if isinstance(value, dict):
            return {key: clean(item) for key, item in value.items()}
        if isinstance(value, list):
            return [clean(item) for item in value]
        return value

    path.write_text(json.dumps(clean(data), indent=1) + "\n")
