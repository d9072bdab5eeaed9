"""The paper's 2-D experiments as studies: the alpha study (Fig. 2) and Alt vs Cont (Fig. 4).
Each writes `summary.json` and the paper's figure into an output folder.
"""

import dataclasses
import json
import math
import pathlib

import numpy as np

from pbp_drake.core.methods import methods_of
from pbp_drake.core.toy_scene import collision_ratio
from pbp_drake.scenarios import AlphaStudy, AltVsCont, resolve
from pbp_drake.scenarios.schema import alpha_key
from pbp_drake.builder.run import simulate
from pbp_drake.studies.atomic_files import write_atomically
from pbp_drake.studies.figures import plot_alpha_study, plot_alt_vs_cont
from pbp_drake.studies.folders import folder_kind, study_lock
from pbp_drake.studies.trial_files import StudyFolderError
from pbp_drake.studies.summary import collision_free, ideal_alpha


# The figure each 2-D study writes beside its summary.json.
TOY_FIGURES = {"alpha_study": "fig2_alpha_study.png", "alt_vs_cont": "fig4_alt_vs_cont.png"}


def run_study(scenario_file, output_dir):
    """Runs the study a scenario file describes; returns its summary. Raises
    StudyFolderError when `output_dir` holds a study of another kind, FolderLocked when
    another study is writing it."""
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
    with study_lock(output_dir):
        return run(scenario_file.resolved, scenario_file.study, output_dir)


def scene_scenario(scenario, scene):
    """The scenario with a scene's obstacles."""
    return dataclasses.replace(scenario, name=f"{scenario.name}/{scene.name}",
                               obstacles=list(scene.obstacles))


#: The paper's two PBP modes, which the alpha study runs beside every fixed alpha.
PBP_METHODS = methods_of("pbp")


def operator_speeds(scenario, study):
    """The operator speeds each scene runs at: the study's `operator_speeds` and the
    scenario operator's own speed (None for an operator without one), the speed
    `pbp-drake run` shows, last unless listed."""
    speeds = list(study.operator_speeds)
    own = getattr(scenario.operator, "speed", None)
    return speeds if speed_key(own) in map(speed_key, speeds) else speeds + [own]


def speed_key(speed):
    """How the summary names an operator speed (`None`: the operator has none)."""
    return "-" if speed is None else f"{speed:g}"


def with_operator_speed(scenario, speed):
    """The scenario with its virtual operator pushing at `speed` (None: unchanged)."""
    if speed is None:
        return scenario
    return dataclasses.replace(scenario, operator=dataclasses.replace(scenario.operator,
                                                                      speed=float(speed)))


def run_outcome(run, obstacles, goal, goal_tolerance):
    """One run's collision ratio, final distance to the goal and whether it was reached."""
    final_distance = float(np.linalg.norm(run.positions[-1] - goal))
    ratio = collision_ratio(run.positions, [o.center for o in obstacles],
                            [o.radius for o in obstacles])
    return {"collision_ratio": ratio, "final_distance": final_distance,
            "reached": final_distance <= goal_tolerance}


def run_alpha_study(resolved, study, output_dir):
    """Explicit arbitration over alpha (P: the demonstration, open loop) against PBP-Alt and
    PBP-Cont (P: a DMP learned from it), the same virtual operator in every run of a scene
    and speed; each scene runs at each of the study's operator speeds."""
    scenario = resolved.scenario
    goal = resolved.goals[0]
    speeds = operator_speeds(scenario, study)
    scenes = []
    trajectories = {}
    for scene in study.scenes:
        # Each (scene, speed) is resolved once; its methods share its DMPs.
        by_speed = {}
        for speed in speeds:
            base = resolve(with_operator_speed(scene_scenario(scenario, scene), speed))
            by_speed[speed_key(speed)] = _scene_at_speed(base, study, scene, goal, speed,
                                                         trajectories)
        scenes.append({
            "name": scene.name,
            "obstacles": [dataclasses.asdict(o) for o in scene.obstacles],
            "by_operator_speed": by_speed,
        })
    summary = {"study": "alpha_study", "scenario": scenario.name, "alphas": study.alphas,
               "goal": goal.tolist(), "goal_tolerance": study.goal_tolerance,
               "operator_speeds": speeds,
               "ideal_alpha_criterion": "highest alpha with no collision (the paper's); "
                                        "reaching the goal is reported, not judged",
               "scenes": scenes}
    _write_json(output_dir / "summary.json", summary)
    plot_alpha_study(resolved, study, summary, trajectories,
                     output_dir / TOY_FIGURES["alpha_study"])
    return summary


def _scene_at_speed(base, study, scene, goal, speed, trajectories):
    """One scene at one operator speed: every fixed alpha, then PBP-Alt and PBP-Cont."""
    fixed = {}
    for alpha in study.alphas:
        run = simulate(base.with_method(f"fixed_alpha={alpha!r}"))
        fixed[alpha_key(alpha)] = run_outcome(run, scene.obstacles, goal, study.goal_tolerance)
        trajectories[(scene.name, speed_key(speed), alpha)] = run.positions
    # The highest alpha that still lets the operator pass the obstacles untouched.
    results = {"operator_speed": speed, "ideal_alpha": ideal_alpha(
        [(alpha, fixed[alpha_key(alpha)]["collision_ratio"]) for alpha in study.alphas],
        collision_free), "fixed_alpha": fixed}
    pushes = []
    for method in PBP_METHODS:
        run = simulate(base.with_method(method))
        results[method] = run_outcome(run, scene.obstacles, goal, study.goal_tolerance)
        trajectories[(scene.name, speed_key(speed), method)] = run.positions
        pushes.append(np.linalg.norm(run.operator_command, axis=-1).max())
    # The fastest push the operator gave in PBP's runs, as measured: the speed it was set to
    # whenever it acted at all (0: it never did).
    results["measured_operator_speed"] = float(max(pushes))
    return results


def print_alpha_study(summary):
    """Prints the ideal alpha and PBP's outcomes per scene and operator speed."""
    tolerance = summary["goal_tolerance"]
    print(f"  (collision ratio / final distance to the goal; reached: within {tolerance:g})")
    for scene in summary["scenes"]:
        for key, results in scene["by_operator_speed"].items():
            fixed = results["fixed_alpha"]
            ideal = results["ideal_alpha"]
            ideal_text = "none" if ideal is None else (
                f"{ideal:g} ({_outcome_text(fixed[alpha_key(ideal)])})")
            reaching = sum(outcome["reached"] for outcome in fixed.values())
            print(f"  {scene['name']}, operator speed {key}: ideal alpha {ideal_text}; "
                  f"{reaching} of {len(fixed)} alphas reach the goal; "
                  f"PBP-Alt {_outcome_text(results['pbp_alternated'])}; "
                  f"PBP-Cont {_outcome_text(results['pbp_continuous'])}")


def _outcome_text(outcome):
    return (f"{outcome['collision_ratio']:.3f} / {outcome['final_distance']:.3f}"
            f"{' reached' if outcome['reached'] else ' NOT reached'}")


def phase_progress(phase, alpha_x):
    """The phase as progress `phi = -ln(x) / alpha_x` (`t / tau` while never locked), the
    increasing phase axis of the paper's Fig. 4."""
    return -np.log(np.maximum(phase, 1e-300)) / alpha_x


def run_alt_vs_cont(resolved, study, output_dir):
    """The same DMP under the same open-loop input in continuous and alternated mode."""
    scenario = resolved.scenario
    goal = resolved.goals[0]
    modes = {}
    for method in ("pbp_continuous", "pbp_alternated"):
        run = simulate(resolved.with_method(method))
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
    plot_alt_vs_cont(resolved, summary, output_dir / TOY_FIGURES["alt_vs_cont"])
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

    write_atomically(path, json.dumps(clean(data), indent=1) + "\n")
