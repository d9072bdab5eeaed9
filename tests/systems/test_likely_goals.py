"""A drawing of K goals' DMP paths costs the same whatever K: `LikelyGoals` picks the
selected goal and the most probable others, and `DmpBank` with `predicted_goal_count` rolls
out those goals' paths alone, the same paths, bit for bit, as rolling out all K."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from test_dmp_bank_compact import GOALS, DT, distinct_bank, drive, shared_bank

from pbp_drake.systems import LikelyGoals
from pbp_drake.systems.pbp.dmp_bank import DmpBank
from pbp_drake.systems.pbp.likely_goals import likely_goal_indices
from pbp_drake_bench.cases import make_bank
from pbp_drake_bench.pose_cases import make_pose_case


@pytest.mark.parametrize("selected, count, expected", [
    (0, 3, [0, 1, 2]),     # the selected goal first, then by probability
    (1, 3, [1, 2, 3]),     # the selected goal is not repeated; a tie goes to the lower index
    (4, 5, [4, 1, 2, 3, 0]),
    (3, 1, [3])])
def test_the_selected_goal_comes_first_then_the_most_probable_others(selected, count,
                                                                     expected):
    probabilities = [0.1, 0.4, 0.2, 0.2, 0.1]
    assert likely_goal_indices(selected, probabilities, count).tolist() == expected


def test_the_system_reads_its_ports_and_refuses_more_goals_than_there_are():
    system = LikelyGoals(5, 2)
    context = system.CreateDefaultContext()
    system.get_selected_goal_input_port().FixValue(context, [3.0])
    system.get_goal_probabilities_input_port().FixValue(context, [0.1, 0.1, 0.6, 0.1, 0.1])
    assert system.get_goal_indices_output_port().Eval(context).tolist() == [3.0, 2.0]
    with pytest.raises(ValueError, match=r"count must be in \[1, 5\]"):
        LikelyGoals(5, 6)


@pytest.mark.parametrize("make_bank", [shared_bank, distinct_bank], ids=["shared", "distinct"])
def test_the_chosen_goals_paths_are_the_all_goal_paths_rows(make_bank):
    bank = make_bank()
    compact = bank.affine_in_goal  # the compact state takes shared weights only
    every = DmpBank(bank, DT, prediction_steps=5, compact_state=compact)
    chosen = DmpBank(bank, DT, prediction_steps=5, compact_state=compact, predicted_goal_count=2)
    contexts = []
    for system in (every, chosen):
        simulator = Simulator(system)
        contexts.append(simulator.get_mutable_context())
        for step in range(12):
            drive(system, contexts[-1], step)
            simulator.AdvanceTo(step * DT + DT / 2)
    chosen.get_predicted_goals_input_port().FixValue(contexts[1], [2.0, 0.0])
    all_paths = every.get_predicted_paths_output_port().Eval(contexts[0]).reshape(
        len(GOALS), 6, 3)
    paths = chosen.get_predicted_paths_output_port().Eval(contexts[1]).reshape(2, 6, 3)
    np.testing.assert_array_equal(paths, all_paths[[2, 0]])
    chosen.get_predicted_goals_input_port().FixValue(contexts[1], [len(GOALS), 0.0])
    with pytest.raises(ValueError, match="indices must be one or more"):
        chosen.get_predicted_paths_output_port().Eval(contexts[1])


@pytest.mark.parametrize("distinct", [False, True], ids=["shared", "distinct"])
def test_a_pose_banks_subset_rolls_out_its_goals_as_the_whole_bank_does(distinct):
    # The grasp drawing rolls out the selected DMP alone, from banks of its one DMP.
    case, orientations, goals, _ = make_pose_case(300, distinct)
    positions = make_bank(case)
    phase, stepped, velocity = positions.initial_state()
    turn_phase, rotations, eta = orientations.initial_state()
    stepped, eta = stepped + 0.01, eta + 0.1
    chosen = [123, 7]
    whole = orientations.predict(turn_phase, rotations, eta, goals.T[3:], 0.05, 30)[chosen]
    alone = orientations.subset(chosen).predict(
        turn_phase[chosen], rotations[:, chosen], eta[:, chosen], goals.T[3:, chosen], 0.05, 30)
    np.testing.assert_allclose(alone, whole, atol=1e-12)  # BLAS may sum in another order
    whole = positions.predict(phase, stepped, velocity, goals.T[:3], 0.05, 30)[chosen]
    alone = positions.subset(chosen).predict(
        phase[chosen], stepped[:, chosen], velocity[:, chosen], goals.T[:3, chosen], 0.05, 30)
    np.testing.assert_array_equal(alone, whole)
    with pytest.raises(ValueError, match="indices must be one or more"):
        orientations.subset([300])
