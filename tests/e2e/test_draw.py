"""`pbp-drake draw`: each scenario's system diagram as SVG. The drawings in diagrams/ are
checked in beside their YAML and must match what `draw` produces now."""

import os
import pathlib
import re

import pytest

from pbp_drake.builder import build_diagram
from pbp_drake.draw import dot_program, dot_source, main, scenario_svg
from pbp_drake.scenarios import load_scenario_file

# Whole tasks, studies, notebooks, browsers or pip: `make test-fast` leaves these out.
pytestmark = pytest.mark.slow

DIAGRAMS = pathlib.Path(__file__).resolve().parents[2] / "diagrams"
SCENARIOS = sorted(DIAGRAMS.glob("*.yaml"))
needs_dot = pytest.mark.skipif(dot_program() is None,
                               reason="graphviz's dot is missing (make test installs it)")


def test_every_scenario_has_its_drawing_beside_it():
    assert SCENARIOS
    missing = [path.name for path in SCENARIOS if not path.with_suffix(".svg").is_file()]
    assert not missing, f"draw them with: python -m pbp_drake.draw diagrams/*.yaml ({missing})"


@needs_dot
@pytest.mark.parametrize("path", SCENARIOS, ids=lambda path: path.stem)
def test_the_checked_in_drawing_is_up_to_date(path):
    drawn = scenario_svg(load_scenario_file(path).scenario)
    assert drawn == path.with_suffix(".svg").read_bytes(), (
        f"{path.with_suffix('.svg').name} is out of date: run "
        f"python -m pbp_drake.draw diagrams/{path.name}")


def test_the_dot_source_does_not_depend_on_what_was_built_before():
    scenario = load_scenario_file(DIAGRAMS / "toy_alpha_study.yaml").scenario
    first = dot_source(build_diagram(scenario))
    # Systems built in between shift Drake's system ids; the source must not change.
    build_diagram(scenario)
    second = dot_source(build_diagram(scenario))
    assert first == second
    assert first.startswith("digraph _0 {")
    assert "name=blender" in first and "name=dmp_bank" in first


@needs_dot
def test_draw_writes_an_svg_where_asked(tmp_path, capsys):
    output = tmp_path / "drawing.svg"
    assert main([str(DIAGRAMS / "toy_alt_vs_cont.yaml"), "--output", str(output)]) == 0
    svg = output.read_text()
    assert svg.lstrip().startswith("<?xml") and "<svg" in svg and "blender" in svg
    # --check agrees with what was just written, and flags a stale file.
    assert main([str(DIAGRAMS / "toy_alt_vs_cont.yaml"), "--output", str(output),
                 "--check"]) == 0
    output.write_text(svg.replace("blender", "mixer"))
    assert main([str(DIAGRAMS / "toy_alt_vs_cont.yaml"), "--output", str(output),
                 "--check"]) == 1
    assert "out of date" in capsys.readouterr().err


def test_draw_with_another_method_draws_another_diagram(tmp_path):
    path = str(DIAGRAMS / "toy_alpha_study.yaml")
    pbp, explicit = tmp_path / "pbp.dot", tmp_path / "fixed.dot"
    assert main([path, "--format", "dot", "--output", str(pbp)]) == 0
    assert main([path, "--format", "dot", "--method", "fixed_alpha", "--output",
                 str(explicit)]) == 0
    assert "name=dmp_bank" in pbp.read_text()
    assert "name=demonstration_player" in explicit.read_text()


def test_draw_writes_the_dot_source_to_standard_output(capsysbinary):
    assert main([str(DIAGRAMS / "toy_alt_vs_cont.yaml"), "--format", "dot", "--output",
                 "-"]) == 0
    out = capsysbinary.readouterr().out.decode()
    assert out.startswith("digraph _0 {") and "name=blender" in out


def test_draw_writes_one_scenario_to_an_output(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main([str(DIAGRAMS / "toy_alt_vs_cont.yaml"), str(DIAGRAMS / "hsr_reach.yaml"),
              "--output", str(tmp_path / "both.svg")])
    assert exit_info.value.code == 2
    assert "--output takes one scenario" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


def test_draw_names_a_bad_scenario(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text((DIAGRAMS / "toy_alt_vs_cont.yaml").read_text().replace(
        "method: pbp_alternated", "method: pbp_alternatd"))
    assert main([str(bad), "--output", str(tmp_path / "bad.svg")]) == 2
    assert "pbp_alternatd" in capsys.readouterr().err
    assert not (tmp_path / "bad.svg").exists()


@pytest.mark.parametrize("argv, message", [
    (["--output", "{tmp}"], "--output {tmp}: is a folder; give a file"),
    (["--output", "{tmp}/notes.txt/toy.svg"],
     "--output {tmp}/notes.txt/toy.svg: {tmp}/notes.txt is a file, so its folder cannot be made"),
    (["--output", ""], "--output: the path is empty"),
    (["--method", ""], "method '' is unknown"),  # was the file's method, in silence
])
def test_draw_names_a_bad_output_or_method_in_one_line(tmp_path, capsys, monkeypatch, argv,
                                                       message):
    monkeypatch.chdir(tmp_path)  # where `--output ''` wrote beside the scenario, it is here
    (tmp_path / "notes.txt").write_text("not a folder")
    scenario = tmp_path / "toy.yaml"
    scenario.write_text((DIAGRAMS / "toy_alt_vs_cont.yaml").read_text())
    argv = [arg.replace("{tmp}", str(tmp_path)) for arg in argv]
    assert main([str(scenario), "--format", "dot", *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pbp-drake draw: ") and len(err.splitlines()) == 1
    assert message.replace("{tmp}", str(tmp_path)) in err
    assert sorted(path.name for path in tmp_path.iterdir()) == ["notes.txt", "toy.yaml"]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes")
@pytest.mark.timeout(60)
@pytest.mark.parametrize("given", [True, False], ids=["--output", "beside the scenario"])
def test_draw_refuses_a_pipe_or_a_device_in_one_line(tmp_path, capsys, given):
    # A pipe's open waited for ever for a reader; /dev/full was an OSError traceback.
    scenario = tmp_path / "toy.yaml"
    scenario.write_text((DIAGRAMS / "toy_alt_vs_cont.yaml").read_text())
    os.mkfifo(tmp_path / "toy.dot")
    for output in ([tmp_path / "toy.dot", "/dev/full"] if given else [tmp_path / "toy.dot"]):
        argv = [str(scenario), "--format", "dot", *(["--output", str(output)] if given else [])]
        assert main(argv) == 2
        assert capsys.readouterr().err == (
            f"pbp-drake draw: --output {output}: is not a regular file (a device or a pipe); "
            "give a file, or - for standard output\n")
    assert (tmp_path / "toy.dot").is_fifo()


@pytest.mark.parametrize("depth", ["-1", "one"])
def test_draw_refuses_a_depth_below_zero(capsys, depth):
    with pytest.raises(SystemExit) as exit_info:
        main([str(DIAGRAMS / "toy_alt_vs_cont.yaml"), "--depth", depth])
    assert exit_info.value.code == 2
    assert "argument --depth: " in capsys.readouterr().err  # not Drake's max_depth failure


def test_draw_without_graphviz_says_what_to_install(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr("pbp_drake.draw.dot_program", lambda: None)
    assert main([str(DIAGRAMS / "toy_alt_vs_cont.yaml"), "--output",
                 str(tmp_path / "x.svg")]) == 2
    assert "graphviz" in capsys.readouterr().err


@needs_dot
def test_pbp_drake_draw_is_the_same_command(tmp_path, capsys):
    from pbp_drake.cli import main as pbp_drake

    output = tmp_path / "drawing.svg"
    path = DIAGRAMS / "toy_alt_vs_cont.yaml"
    try:
        code = pbp_drake(["draw", str(path), "--output", str(output)])
    except SystemExit:
        pytest.skip("`pbp-drake draw` is not hooked into the CLI yet")
    assert code == 0
    assert output.read_bytes() == path.with_suffix(".svg").read_bytes()


def test_the_hsr_task_drawing_has_the_station_as_one_block_at_page_width():
    svg = (DIAGRAMS / "hsr_reach.svg").read_text()
    width = float(re.search(r'<svg width="([\d.]+)pt"', svg).group(1))
    assert width <= 1000  # a README page is about 1000 pt wide
    assert "name=hsr_station" in svg and "name=pbp_controller" in svg
    assert "MultibodyPlant" not in svg and "DmpBank" not in svg  # inside the blocks
