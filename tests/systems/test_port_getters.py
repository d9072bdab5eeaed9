"""Port getters come from the ports a system declares (`PortGetters`):
`get_NAME_input_port()` is `GetInputPort(NAME)` for every input port NAME, and likewise for
the outputs; no module writes one of its own for a port of the same name. A docstring's port
block names the ports declared, and says under which arguments one is."""

import ast
import pathlib
import re

import numpy as np
import pytest

from pbp_drake.core.dmp import DmpBankModel
from pbp_drake.systems.operators.virtual_operator import VirtualOperator
from pbp_drake.systems.pbp.dmp_bank import DmpBank
from pbp_drake.systems.tasks.task_monitor import TaskMonitor

PACKAGE = pathlib.Path(__file__).resolve().parents[2] / "pbp_drake"


def _ports(system, kind):
    count = system.num_input_ports() if kind == "input" else system.num_output_ports()
    get = system.get_input_port if kind == "input" else system.get_output_port
    return [get(i) for i in range(count)]


@pytest.mark.parametrize("kind", ["input", "output"])
def test_every_declared_port_has_its_getter(kind):
    system = DmpBank(DmpBankModel.straight(np.zeros(3), 4, 1.0), 0.01, prediction_steps=3)
    ports = _ports(system, kind)
    assert len(ports) >= 4
    for port in ports:
        getter = f"get_{port.get_name()}_{kind}_port"
        assert getattr(system, getter)().get_index() == port.get_index()
        assert getter in dir(system)


def test_a_port_the_system_did_not_declare_has_no_getter():
    system = DmpBank(DmpBankModel.straight(np.zeros(3), 4, 1.0), 0.01)  # no prediction
    assert not system.HasOutputPort("predicted_paths")
    with pytest.raises(AttributeError, match="get_predicted_paths_output_port"):
        system.get_predicted_paths_output_port()
    with pytest.raises(AttributeError, match="get_goals_output_port"):
        system.get_goals_output_port()  # `goals` is an input
    assert "get_predicted_paths_output_port" not in dir(system)


def test_a_subclass_gets_the_getters_of_its_own_ports():
    monitor = TaskMonitor([[0.5, 0.0, 0.4]], [0], [0.0], [0.0, 0.0, 0.0], 0.05, 0.02)
    assert monitor.get_ee_state_input_port().get_name() == "ee_state"
    assert monitor.get_task_status_output_port().get_name() == "task_status"


def _declared_names(cls):
    names = set()
    for node in ast.walk(cls):
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                and re.fullmatch(r"Declare\w*(Input|Output)Port", node.func.attr)
                and node.args and isinstance(node.args[0], ast.Constant)):
            kind = "input" if "Input" in node.func.attr else "output"
            names.add(f"get_{node.args[0].value}_{kind}_port")
    return names


@pytest.mark.slow
def test_no_module_writes_a_getter_the_ports_give():
    written = []
    for path in sorted(PACKAGE.rglob("*.py")):
        for cls in ast.walk(ast.parse(path.read_text())):
            if isinstance(cls, ast.ClassDef):
                declared = _declared_names(cls)
                written += [f"{path.name}: {cls.name}.{method.name}" for method in cls.body
                            if isinstance(method, ast.FunctionDef) and method.name in declared]
    assert not written


def _documented_ports(system):
    """{port name: its note in parentheses, or ""} of the docstring's `pydrake_system` block."""
    block = type(system).__doc__.split(".. pydrake_system::")[1].split("\n\n")[1]
    return {match[0]: match[1] for match in re.findall(r"^\s*- (\w+)(?: \((.*)\))?$", block,
                                                        re.M)}


@pytest.mark.parametrize("build, build_all", [
    (lambda: DmpBank(DmpBankModel.straight(np.zeros(3), 4, 1.0), 0.01),
     lambda: DmpBank(DmpBankModel.straight(np.zeros(3), 4, 1.0), 0.01, prediction_steps=3,
                     predicted_goal_count=2)),
    (lambda: VirtualOperator(0.03, [[1.0, 0.0, 0.7]], nominal_speed=0.12),
     lambda: VirtualOperator(0.03, [[1.0, 0.0, 0.7]], nominal_speed=0.12, obstacle_count=2,
                             obstacle_radius=0.2)),
])
def test_a_port_the_docstring_calls_optional_is_always_there_and_one_not_always_says_when(
        build, build_all):
    # An "(optional)" port may be left unconnected; a port declared only under some
    # arguments is not optional where it is declared, and its note says when it is.
    plain, full = build(), build_all()
    notes = _documented_ports(full)
    declared = {port.get_name() for kind in ("input", "output") for port in _ports(full, kind)}
    assert set(notes) == declared
    always = {port.get_name() for kind in ("input", "output") for port in _ports(plain, kind)}
    for name, note in notes.items():
        if name not in always:
            assert note.startswith("with "), f"{name} ({note}) is declared only with some arguments"
