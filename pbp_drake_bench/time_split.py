"""Where a closed-loop tick's wall time goes: one run under cProfile, each function's own
time (tottime) given to a category.

A function of pbp_drake goes to its file's category (`CATEGORIES`, by path under the
package; "rest" for the package's other systems: task monitor, tick, sample-hold, the
builder). Any other function (NumPy, pydrake's bindings, the standard library) and the
package's shared helpers (quaternions, ports, linear algebra) are split over their callers
in proportion to the time each caller edge took (pstats' per-caller cumulative time),
recursively up the call graph, so NumPy called by the DMP bank counts as the bank. Meshcat's
own methods go to drawing whoever calls them. What has no caller left (Drake's
`Simulator.AdvanceTo` itself: its framework, the plant, Drake's C++ MeshcatVisualizer of
the robot) is "rest". The categories' times sum to the profile's total.

cProfile adds a cost to every Python call: the Python-heavy parts (the tick's systems, the
diff IK) look larger against Drake's C++ than they are without it."""

import cProfile
import pstats

from pydrake.geometry import Meshcat

BANK, ESTIMATOR, BLENDER, IK, DRAWING, OPERATOR, REST = (
    "bank", "estimator", "blender", "IK", "drawing", "operator", "rest")
ORDER = (BANK, ESTIMATOR, BLENDER, IK, DRAWING, OPERATOR, REST)
# Paths under pbp_drake/ (a file, or a folder ending in /) and their category; the longest
# match wins. SHARED: split over its callers like code outside the package.
SHARED = "shared"
CATEGORIES = {
    "systems/pbp/dmp_bank.py": BANK, "systems/pbp/dmp_bank_state.py": BANK,
    "systems/pbp/pose_dmp_bank.py": BANK, "systems/pbp/pose_dmp_bank_state.py": BANK,
    "systems/pbp/goals_source.py": BANK, "core/dmp/": BANK,
    "systems/pbp/demonstration_player.py": BANK,  # explicit arbitration's policy
    "systems/pbp/goal_estimator.py": ESTIMATOR, "systems/pbp/maxent_goal_estimator.py": ESTIMATOR,
    "systems/pbp/pose_goal_estimator.py": ESTIMATOR,
    "systems/pbp/pose_maxent_goal_estimator.py": ESTIMATOR,
    "core/goal_estimation.py": ESTIMATOR, "core/grasp_estimation.py": ESTIMATOR,
    "core/hindsight_optimization.py": ESTIMATOR, "systems/pbp/goal_grouping.py": ESTIMATOR,
    "core/goal_groups.py": ESTIMATOR, "systems/pbp/intent_filter_estimator.py": ESTIMATOR,
    "core/intent_filter.py": ESTIMATOR, "core/maxent_command.py": ESTIMATOR,
    "systems/pbp/blender.py": BLENDER, "systems/pbp/pose_blender.py": BLENDER,
    "systems/pbp/hand_over.py": BLENDER, "systems/pbp/pose_hand_over.py": BLENDER,
    "systems/pbp/heading_command.py": BLENDER, "systems/pbp/hop_assistance.py": BLENDER,
    "systems/pbp/pose_hop_assistance.py": BLENDER, "core/arbitration.py": BLENDER,
    "core/pose_arbitration.py": BLENDER, "core/hand_over.py": BLENDER,
    "robots/": IK,
    "systems/visualizers/": DRAWING, "systems/pbp/likely_goals.py": DRAWING,
    "core/scene_framing.py": DRAWING,
    "systems/operators/": OPERATOR, "core/participant_": OPERATOR,
    "core/operator_frame.py": OPERATOR,
    "systems/tasks/": REST, "systems/tick.py": REST, "systems/sample_hold.py": REST,
    "builder/": REST, "console/": REST, "scenarios/": REST,
    "core/": SHARED, "systems/": SHARED,
}
_PACKAGE = "/pbp_drake/"
_BENCH = "/pbp_drake_bench/"  # the bench's own code: rest
_MESHCAT_METHODS = frozenset(name for name in dir(Meshcat) if not name.startswith("__"))


def category_of(function):
    """The category of a pstats function key `(file, line, name)`, or None to split it over
    its callers."""
    path, _, name = function
    at = path.replace("\\", "/").rfind(_PACKAGE)
    if at >= 0 and ".venv" not in path and "site-packages" not in path:
        relative = path.replace("\\", "/")[at + len(_PACKAGE):]
        matches = [prefix for prefix in CATEGORIES if relative.startswith(prefix)]
        category = CATEGORIES[max(matches, key=len)] if matches else REST
        return None if category == SHARED else category
    if _BENCH in path.replace("\\", "/"):
        return REST
    if name.startswith("<built-in method pydrake.geometry.") and (
            name[len("<built-in method pydrake.geometry."):-1] in _MESHCAT_METHODS):
        return DRAWING
    return None


def split_stats(stats):
    """`{category: seconds}` over `ORDER` of a `pstats.Stats`' own times (see the module)."""
    table = stats.stats
    shares = {}

    def share(function, visiting):
        if function in shares:
            return shares[function]
        category = category_of(function)
        if category is not None:
            result = {category: 1.0}
        else:
            callers = {caller: edge for caller, edge in table[function][4].items()
                       if caller in table and caller not in visiting}
            weights = {caller: edge[3] for caller, edge in callers.items()}
            if callers and sum(weights.values()) <= 0.0:  # no time measured: by calls
                weights = {caller: edge[1] for caller, edge in callers.items()}
            total = sum(weights.values())
            result = {}
            if total <= 0.0:
                result = {REST: 1.0}
            else:
                for caller, weight in weights.items():
                    for name, part in share(caller, visiting | {function}).items():
                        result[name] = result.get(name, 0.0) + part * weight / total
        # Kept even when found inside a cycle (its edge back to a caller being visited is
        # left out): every share sums to 1 either way, and each function is split once.
        shares[function] = result
        return result

    seconds = dict.fromkeys(ORDER, 0.0)
    for function, (_, _, own, _, _) in table.items():
        for name, part in share(function, frozenset()).items():
            seconds[name] += own * part
    return seconds


def profiled_advance(advance):
    """`(advance()'s result, {category: seconds}, total profiled seconds)`: `advance` run
    under cProfile."""
    profile = cProfile.Profile()
    profile.enable()
    try:
        result = advance()
    finally:
        profile.disable()
    stats = pstats.Stats(profile)
    seconds = split_stats(stats)
    return result, seconds, stats.total_tt


def split_row(seconds, total, ticks):
    """A report row: per category its milliseconds per tick and share of the profile."""
    return {"ticks": ticks, "profiled_ms_per_tick": 1e3 * total / ticks,
            "ms_per_tick": {name: 1e3 * seconds[name] / ticks for name in ORDER},
            "share": {name: seconds[name] / total if total else 0.0 for name in ORDER}}
