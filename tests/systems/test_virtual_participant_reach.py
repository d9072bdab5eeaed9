"""The virtual participant in the reaching task: its fields come from the scenario, and
while the estimate names the wrong object it shows the target in a way every shipped goal
estimator reads."""

import numpy as np
import pytest
from pydrake.common.yaml import yaml_load_typed
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from pbp_drake.builder import build_diagram
from pbp_drake.core.goal_estimation import GoalEstimatorSettings, goal_probabilities
from pbp_drake.core.participant_params import VirtualParticipantParams
from pbp_drake.core.participant_reach import assist_motion, facing
from pbp_drake.scenarios import TaskScenario, resolve
from pbp_drake.systems import VirtualOperator

PERIOD = 0.03
SPEED = 0.12
START = np.array([0.5, 0.0, 0.7])
# Seen from START facing +x: the picked object ahead-left, the target ahead-right.
PICKED_LEFT = np.array([1.6, 0.5, 0.7])
TARGET_RIGHT = np.array([1.6, -0.5, 0.7])
ESTIMATORS = [GoalEstimatorSettings(method=method)
              for method in ("angle", "nearest", "bayesian")]


def target_probability(settings, goals, position, heading):
    return goal_probabilities(settings, goals, position, heading, start=START,
                              path_length=0.0)[1]


def participant_command(params, ee_state, target, target_index, selected, objects,
                        ticks=1):
    """The operator command of a lone participant after `ticks` control ticks with the
    given inputs held, the robot showing `selected` and the forward key disabled (PBP)."""
    builder = DiagramBuilder()
    participant = builder.AddSystem(VirtualOperator(PERIOD, objects, params=params,
                                                    nominal_speed=SPEED))
    for port, value in ((participant.get_ee_state_input_port(), ee_state),
                        (participant.get_target_input_port(), [*target, target_index]),
                        (participant.get_selected_goal_input_port(), [selected]),
                        (participant.get_forward_key_input_port(), [0.0])):
        source = builder.AddSystem(ConstantVectorSource(np.asarray(value, dtype=float)))
        builder.Connect(source.get_output_port(), port)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.AdvanceTo((ticks - 0.5) * PERIOD)
    context = participant.GetMyContextFromRoot(simulator.get_context())
    return participant.get_operator_command_output_port().Eval(context)


def test_the_participant_fields_are_scenario_fields():
    text = ("robot: !Hsr {}\ntask: {}\ncontrol_period: 0.03\n"
            "operator: !VirtualParticipant {insist_time: 0.0, in_line_angle: 0.2}\n")
    diagram = build_diagram(resolve(yaml_load_typed(schema=TaskScenario, data=text)), None)
    params = diagram.GetSubsystemByName("operator").params
    assert params.insist_time == 0.0 and params.in_line_angle == 0.2
    # With no patience at all it turns the target to its side at once, though it faces
    # it; with the default it keeps facing it for a while and only sidesteps.
    objects = np.array([PICKED_LEFT, [2.4, 0.0, 0.7]])
    facing_target = [*START, 0, 0, 0, 0.0, 0.0]
    impatient = participant_command(params, facing_target, objects[1], 1, 0, objects)
    patient = participant_command(VirtualParticipantParams(), facing_target, objects[1], 1, 0,
                                  objects)
    assert abs(impatient[3]) > 0.1
    assert patient[3] == 0.0 and np.linalg.norm(patient[:2]) > 0.05


@pytest.mark.parametrize("heading", [0.0, 0.4, -0.3])
def test_a_wrong_estimate_moves_the_hand_to_the_target_side_and_never_forward(heading):
    params = VirtualParticipantParams()
    velocity, yaw_rate = assist_motion(params, SPEED, START, heading, TARGET_RIGHT,
                                       PICKED_LEFT, insisting=False)
    assert velocity[1] < -0.05  # toward the target's side (right, -y)
    assert velocity @ facing(heading) <= 1e-12  # the forward key is disabled
    # A short stretch of this motion raises the target's probability under every
    # estimator the scenario can choose.
    moved, turned = START + np.append(velocity, 0.0) * 0.3, heading + yaw_rate * 0.3
    goals = np.array([PICKED_LEFT, TARGET_RIGHT])
    for settings in ESTIMATORS:
        assert (target_probability(settings, goals, moved, turned)
                > target_probability(settings, goals, START, heading)), settings.method


def test_facing_a_target_behind_the_picked_object_it_goes_there_itself():
    # The target straight behind the picked object: no sidestep tells them apart by
    # distance, so once insisting the participant turns it to its side and sidesteps to it.
    params = VirtualParticipantParams()
    picked, target = np.array([1.4, 0.0, 0.7]), np.array([2.3, 0.0, 0.7])
    velocity, yaw_rate = assist_motion(params, SPEED, START, 0.0, target, picked,
                                       insisting=False)
    assert yaw_rate == 0.0 and np.linalg.norm(velocity) > 0.0  # it steps aside
    sideways = 1.4  # turned most of the way to put the target on its side
    velocity, yaw_rate = assist_motion(params, SPEED, START, sideways, target, picked,
                                       insisting=True)
    assert abs(yaw_rate) > 0.0
    assert velocity @ facing(sideways) <= 1e-12
    assert velocity[0] > 0.1  # toward the target, at nearly the whole speed



@pytest.mark.parametrize("change, message", [
    ({"objects": []}, r"objects must be a non-empty finite \(M, 3\) array, got shape \(0,\)"),
    ({"objects": [[0.5, 0.0]]}, r"objects must be .* got shape \(1, 2\)"),
    ({"objects": [[np.nan, 0.0, 0.4]]}, r"objects must be a non-empty finite \(M, 3\) array"),
    ({"params": None}, "params must be VirtualParticipantParams, got NoneType"),
    ({"heading_range": (1.0, -1.0)},
     r"heading_range must be \(lowest, highest\) finite headings \(rad\), got \(1.0, -1.0\)"),
    ({"heading_range": (np.nan, 1.0)}, "heading_range must be"),
    ({"seed": 1.5}, "seed must be a whole number >= 0, got 1.5"),
    ({"seed": -1}, "seed must be a whole number >= 0, got -1"),
    ({"params": VirtualParticipantParams(reaction_delay=-0.3)},
     "params.reaction_delay must be finite and not negative, got -0.3"),
    ({"params": VirtualParticipantParams(direction_noise=np.nan)},
     "params.direction_noise must be finite and not negative, got nan"),
    ({"params": VirtualParticipantParams(hold_time=None)},
     "params.hold_time must be finite and not negative, got None"),
])
def test_the_participant_names_an_argument_it_cannot_act_on(change, message):
    arguments = {"control_period": 0.03, "objects": [[0.5, 0.0, 0.4], [0.6, 0.2, 0.4]],
                 "nominal_speed": 0.1, **change}
    with pytest.raises(ValueError, match=message):
        VirtualOperator(**arguments)
