"""Whole reaching tasks with the virtual participant impaired (`impairment`, see
`pbp_drake.core.participant_impairment`): the late participant's first command reaches the
robot its delay after the unimpaired one's; the mistaken one first moves the hand toward
the other object, then reaches the target."""

import dataclasses
import textwrap

import numpy as np
import pytest

from pbp_drake.builder.run import run_task
from pbp_drake.core.participant_impairment import ParticipantImpairment
from pbp_drake.scenarios import load_scenario_file

pytestmark = pytest.mark.slow

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
def two_objects(tmp_path_factory):
    path = tmp_path_factory.mktemp("task") / "two_objects.yaml"
    path.write_text(textwrap.dedent(TWO_OBJECTS))
    return load_scenario_file(path).scenario


def impaired(scenario, **fields):
    operator = dataclasses.replace(scenario.operator,
                                   impairment=ParticipantImpairment(**fields))
    return dataclasses.replace(scenario, operator=operator)


def test_the_late_participants_commands_reach_the_robot_its_delay_later(two_objects):
    on_time = run_task(two_objects)
    late = run_task(impaired(two_objects, command_delay=0.3))
    # Under teleop it first watches the still robot (serve_patience), then presses.
    first = int(np.argmax(on_time.operator_active))
    assert 0 < first and not on_time.operator_active[:first].any()
    assert not late.operator_active[:first + 10].any() and late.operator_active[first + 10]
    # Until its late commands move the hand, they are the unimpaired participant's.
    assert np.array_equal(late.operator_commands[first + 10:first + 11],
                          on_time.operator_commands[first:first + 1])
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
