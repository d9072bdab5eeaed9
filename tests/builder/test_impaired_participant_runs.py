"""Whole reaching tasks with the virtual participant impaired (`impairment`, see
`pbp_drake.core.participant_impairment`), and unimpaired: with the defaults a shipped
scenario runs exactly as it did before impairments existed; the late participant's first
command reaches the robot its delay after the start; the mistaken one first moves the hand
toward the other object, then reaches the target."""

import dataclasses
import textwrap

import numpy as np
import pytest

from pbp_drake.builder.run import run_task
from pbp_drake.core.participant_impairment import ParticipantImpairment
from pbp_drake.scenarios import load_scenario_file

pytestmark = pytest.mark.slow

# diagrams/hsr_reach.yaml, seed 0, as the trials of `pbp-drake study` recorded them at
# commit b54fed1, before the participant had an impairment.
BEFORE_IMPAIRMENTS = {
    "teleop": dict(task_time=16.14, intervention_ratio=0.9369202226345084,
                   peak_hand_speed=0.15068004780204297, switches=2),
    "pbp_alternated": dict(task_time=18.24, intervention_ratio=0.18555008210180624,
                           peak_hand_speed=0.20065164293167792, switches=2),
}

# Two objects side by side; the target is the right one from the start.
TWO_OBJECTS = """
scenario:
  name: two_objects
  method: teleop
  control_period: 0.03
  duration: 30.0
  robot: !Hsr
    station: {plant: {time_step: 0.005}, diff_ik_time_step: 0.01, motion: kinematic}
  task:
    objects: [[1.5, 0.6, 0.7], [1.5, -0.6, 0.7]]
    targets: [1]
    switch_schedule: [0.0]
  operator: !VirtualParticipant {}
  seed: 3
"""


@pytest.fixture(scope="module")
def reach(repo):
    return load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario


@pytest.fixture(scope="module")
def two_objects(tmp_path_factory):
    path = tmp_path_factory.mktemp("task") / "two_objects.yaml"
    path.write_text(textwrap.dedent(TWO_OBJECTS))
    return load_scenario_file(path).scenario


def impaired(scenario, **fields):
    operator = dataclasses.replace(scenario.operator,
                                   impairment=ParticipantImpairment(**fields))
    return dataclasses.replace(scenario, operator=operator)


@pytest.mark.parametrize("method", sorted(BEFORE_IMPAIRMENTS))
def test_the_unimpaired_participant_runs_as_before_impairments_existed(reach, method):
    result = run_task(dataclasses.replace(reach, method=method, seed=0))
    before = BEFORE_IMPAIRMENTS[method]
    assert result.success and result.switches == before["switches"]
    assert result.task_time == pytest.approx(before["task_time"], abs=1e-9)
    assert result.intervention_ratio == pytest.approx(before["intervention_ratio"], rel=1e-12)
    assert result.peak_hand_speed == pytest.approx(before["peak_hand_speed"], rel=1e-12)


def test_the_late_participants_commands_reach_the_robot_its_delay_later(two_objects):
    on_time = run_task(two_objects)
    late = run_task(impaired(two_objects, command_delay=0.3))
    assert on_time.operator_active[0]
    assert not late.operator_active[:10].any() and late.operator_active[10]
    # Until its late commands move the hand, they are the unimpaired participant's.
    assert np.array_equal(late.operator_commands[10:11], on_time.operator_commands[:1])
    assert late.success


def test_the_mistaken_participant_moves_toward_the_other_object_first(two_objects):
    mistaken = run_task(impaired(two_objects, mistake_probability=1.0, mistake_time=1.5))
    start = mistaken.ee_positions[0]
    at_correction = mistaken.ee_positions[int(round(1.5 / 0.03))]
    # Toward the left object (+y), away from the target on the right ...
    assert at_correction[1] - start[1] > 0.05
    # ... then on to the target.
    assert mistaken.success
    assert np.linalg.norm(mistaken.ee_positions[-1] - mistaken.objects[1]) < 0.06
    unimpaired = run_task(two_objects)
    assert unimpaired.ee_positions[int(round(1.5 / 0.03))][1] < start[1]
    assert mistaken.task_time > unimpaired.task_time
