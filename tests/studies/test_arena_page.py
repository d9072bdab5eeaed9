"""The arena page's claims: each a rule on 95 % intervals, checked here on summaries whose
intervals are computed by hand from their definitions; and `make results`' matrix entry
run on a tiny study (two methods, two pilots, a trial each), writing its table, figure and the
page."""

import json
import math

import pytest

from pbp_drake_bench.arena_page import (
    CLAIMS, FAILS, HOLDS, UNDECIDED, arena_page, claims_table, verdict)
from pbp_drake_bench.results_catalogue import ARENA_STUDIES, STUDIES, main

Z = 1.959963984540054
T_29 = 2.045229642132703  # Student's t, 0.975 quantile, 29 degrees of freedom


def entry(trials=30, success=1.0, intervention=(0.1, 0.02), time=(10.0, 1.0), free=None):
    return {"trials": trials, "errors": 0, "missing": 0, "success_rate": success,
            "intervention_ratio": {"mean": intervention[0], "std": intervention[1]},
            "task_time": {"mean": time[0], "std": time[1]},
            **({} if free is None else {"collision_free_trials": free})}


def claim(name):
    return next(c for c in CLAIMS if c.name == name)


def half_width(population_std, n=30):
    """The t interval's half width of a mean of n = 30 values (definition)."""
    return T_29 * population_std * math.sqrt(n / (n - 1)) / math.sqrt(n)


def test_less_input_than_teleop_holds_fails_or_is_undecided_by_the_intervals():
    less = claim("needs less operator input than teleop")
    teleop = entry(intervention=(0.9, 0.02))
    assert verdict(less, entry(intervention=(0.1, 0.02)), teleop)[0] == HOLDS
    # The intervals overlap: 0.91 - half width < 0.9 + half width.
    assert 0.91 - half_width(0.02) < 0.9 + half_width(0.02)
    assert verdict(less, entry(intervention=(0.91, 0.02)), teleop)[0] == UNDECIDED
    # Wholly above teleop's interval: 0.95 - half width > 0.9 + half width.
    assert 0.95 - half_width(0.02) > 0.9 + half_width(0.02)
    assert verdict(less, entry(intervention=(0.95, 0.02)), teleop)[0] == FAILS


def test_a_cut_of_more_than_60_percent_compares_with_0_4_times_teleops_interval():
    cut = claim("cuts teleop's input by more than 60 %")
    teleop = entry(intervention=(0.9, 0.02))
    bound_low = 0.4 * (0.9 - half_width(0.02))
    # Just below the scaled bound holds, just above is undecided.
    below = bound_low - half_width(0.01) - 1e-4
    above = bound_low - half_width(0.01) + 1e-4
    assert verdict(cut, entry(intervention=(below, 0.01)), teleop)[0] == HOLDS
    assert verdict(cut, entry(intervention=(above, 0.01)), teleop)[0] == UNDECIDED


def test_task_time_at_most_1_2_times_teleops():
    time = claim("takes at most 1.2 times teleop's task time")
    teleop = entry(time=(10.0, 1.0))
    assert verdict(time, entry(time=(10.0, 1.0)), teleop)[0] == HOLDS
    assert verdict(time, entry(time=(20.0, 1.0)), teleop)[0] == FAILS
    assert verdict(time, entry(time=(12.0, 1.0)), teleop)[0] == UNDECIDED


def test_success_of_95_percent_needs_a_wilson_interval_above_it():
    success = claim("succeeds in at least 95 % of trials")
    teleop = entry()
    # Every trial a success: Wilson's low end is n / (n + z^2).
    assert 30 / (30 + Z * Z) < 0.95 < 100 / (100 + Z * Z)
    assert verdict(success, entry(trials=30, success=1.0), teleop)[0] == UNDECIDED
    assert verdict(success, entry(trials=100, success=1.0), teleop)[0] == HOLDS
    assert verdict(success, entry(trials=30, success=0.5), teleop)[0] == FAILS


def test_the_claims_a_task_makes_follow_whether_it_measures_collisions():
    methods = {"pbp_alternated": entry(free=25), "teleop": entry(intervention=(0.9, 0.02))}
    reach = {"measures_collisions": False, "pilots": {"noisy": {"methods": methods}}}
    obstacles = {**reach, "measures_collisions": True}
    reach_rows = "\n".join(claims_table(reach, "noisy"))
    obstacle_rows = "\n".join(claims_table(obstacles, "noisy"))
    assert "more than 60 %" in reach_rows and "collisions" not in reach_rows
    assert "more than 40 %" in obstacle_rows and "free of collisions" in obstacle_rows
    assert reach_rows.splitlines()[0] == "| claim | PBP-Alt |"


def test_a_matrix_not_run_yet_is_named_on_the_page(tmp_path):
    page = arena_page(ARENA_STUDIES, tmp_path / "outputs", tmp_path / "generated",
                      tmp_path / "arena.md")
    assert page.count("Not run yet") == len(ARENA_STUDIES)
    for claim_ in CLAIMS:
        assert f"**{claim_.name}**" in page


@pytest.mark.slow
def test_the_catalogues_matrix_writes_its_table_figure_and_the_page(repo, tmp_path,
                                                                    monkeypatch):
    monkeypatch.chdir(repo)  # the catalogue names the scenario files from the repository
    generated, page = tmp_path / "generated", tmp_path / "arena.md"
    name = "hsr_reach_arena"
    # The catalogue's entry with two of its methods under two of its pilots (4 trials, not
    # 25): the page's claims compare PBP-Alt with teleop, and a second pilot makes a matrix.
    arguments = list(STUDIES[name])
    methods, pilots = (arguments.index(flag) + 1 for flag in ("--methods", "--pilots"))
    assert {"pbp_alternated", "teleop"} <= set(arguments[methods].split(","))
    arguments[methods] = "pbp_alternated,teleop"
    arguments[pilots] = ",".join(arguments[pilots].split(",")[:2])
    monkeypatch.setitem(STUDIES, name, arguments)
    assert main([name, "--trials", "1", "--outputs", str(tmp_path / "out"),
                 "--generated", str(generated), "--arena", str(page)]) == 0
    text = (generated / f"{name}.md").read_text()
    assert text.startswith("`pbp-drake study " + " ".join(STUDIES[name]).replace(
        "--trials 30", "--trials 1"))
    assert (generated / f"{name}_pilots.png").stat().st_size > 10_000
    summary = json.loads((tmp_path / "out" / name / "summary.json").read_text())
    written = page.read_text()
    assert written.count("Not run yet") == len(ARENA_STUDIES) - 1
    assert len(summary["pilots"]) == 2
    for pilot in summary["pilots"]:
        assert f"### Pilot: {pilot}" in written
    assert f"```{{include}} generated/{name}.md" in written
    assert f"(generated/{name}_pilots.png)" in written


def test_a_matrix_not_on_disk_keeps_its_published_section(tmp_path):
    # A machine that reruns one matrix keeps the others' sections of the page as they are.
    page_path = tmp_path / "arena.md"
    first = arena_page(ARENA_STUDIES, tmp_path / "outputs", tmp_path / "generated", page_path)
    title = next(iter(ARENA_STUDIES.values()))
    published = first.replace(f"## {title}\n\nNot run yet", f"## {title}\n\nA published table")
    published = published.replace("A published table: `make results` runs it",
                                  "A published table, kept")
    page_path.write_text(published)
    again = arena_page(ARENA_STUDIES, tmp_path / "outputs", tmp_path / "generated", page_path)
    assert again == published
    assert again.count("Not run yet") == len(ARENA_STUDIES) - 1
