"""The goal estimators' step at K goals: each shipped estimator that reads the hand (and the
operator) in a Simulator of its own, at the reaching task's control period, fed by constant
sources (the hand moving and turning, the operator commanding), its outputs read every tick
as the controller reads them; with goal groups, the `GoalGrouping` after it (what a PBP tick
with `goal_estimator: {group_mass: ...}` runs). The times are the median of one control
period's step, and each row's ratio to the ``angle`` estimator's of the same run (the machine
may be loaded: the ratio holds where the absolute times do not).
"""

import dataclasses

import numpy as np
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.builder.pbp_controller import make_goal_estimator
from pbp_drake.systems import GoalGrouping, GoalsSource
from pbp_drake_bench.cases import connect_reader
from pbp_drake_bench.checks import ESTIMATOR_GOALS
from pbp_drake_bench.scenes import hsr_scenario
from pbp_drake_bench.timing import timed
from pbp_drake.scenarios import resolve

GROUP_MASS = 0.9
# (label, estimator, with goal groups) of the rows, `angle` first (the ratios' base).
ROWS = (("angle", "angle", False), ("angle + groups", "angle", True),
        ("nearest", "nearest", False), ("bayesian", "bayesian", False),
        ("maxent_command", "maxent_command", False), ("intent_filter", "intent_filter", False),
        ("intent_filter + groups", "intent_filter", True))
# The hand and the operator the constant sources hold: moving at 0.1 m/s, turning.
HAND = np.array([0.6, 0.05, 0.7, 0.1, 0.02, 0.0, 0.15, 0.3])
COMMAND = np.array([0.08, 0.03, 0.0, 0.4])


def estimator_simulator(config, goals):
    """A Simulator of `config`'s goal estimator (and goal grouping) over `goals` (K, 3)."""
    builder = DiagramBuilder()
    count = len(goals)
    estimator = builder.AddSystem(make_goal_estimator(config, count))
    source = builder.AddSystem(GoalsSource(goals))
    builder.Connect(source.get_output_port(), estimator.get_goals_input_port())
    hand = builder.AddSystem(ConstantVectorSource(HAND))
    builder.Connect(hand.get_output_port(), estimator.get_ee_state_input_port())
    if estimator.HasInputPort("operator_command"):
        command = builder.AddSystem(ConstantVectorSource(COMMAND))
        builder.Connect(command.get_output_port(), estimator.get_operator_command_input_port())
        active = builder.AddSystem(ConstantVectorSource([1.0]))
        builder.Connect(active.get_output_port(), estimator.get_operator_active_input_port())
    read = estimator.get_goal_probabilities_output_port()
    if config.goal_estimator.group_mass > 0.0:
        grouping = builder.AddSystem(GoalGrouping(count, config.goal_estimator,
                                                  config.control_period))
        builder.Connect(source.get_output_port(), grouping.get_goals_input_port())
        builder.Connect(hand.get_output_port(), grouping.get_ee_state_input_port())
        builder.Connect(read, grouping.get_goal_probabilities_input_port())
        builder.Connect(estimator.get_selected_goal_output_port(),
                        grouping.get_selected_goal_input_port())
        read = grouping.get_followed_goals_output_port()
    connect_reader(builder, read, config.control_period)
    simulator = Simulator(builder.Build())
    simulator.Initialize()
    return simulator


def estimator_steps(min_time, goal_count=ESTIMATOR_GOALS, progress=None):
    """{"goals", "period_s", "rows": [{"estimator", "groups", "step_us", "vs_angle"}]}."""
    resolved = resolve(hsr_scenario(goal_count))
    base = resolved.controller
    period = base.control_period
    rows = []
    for label, method, groups in ROWS:
        if progress:
            progress(f"Goal estimator step: {label}, K = {goal_count:,} ...")
        settings = dataclasses.replace(base.goal_estimator, method=method,
                                       group_mass=GROUP_MASS if groups else 0.0)
        simulator = estimator_simulator(dataclasses.replace(base, goal_estimator=settings),
                                        resolved.goals)

        def step():
            simulator.AdvanceTo(simulator.get_context().get_time() + period)

        median, _, _ = timed(step, min_time)
        rows.append({"estimator": label, "groups": groups, "step_us": median * 1e6})
    angle = rows[0]["step_us"]
    for row in rows:
        row["vs_angle"] = row["step_us"] / angle
    return {"goals": goal_count, "period_s": period, "rows": rows}
