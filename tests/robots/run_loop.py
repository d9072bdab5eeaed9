"""`task_runs.run_task_loop` with a page, nothing built or run (a test helper): each run
ends with the next of `choices` (Restart, Next scene, Stop); returns what `on_build` made
of each `ResolvedScenario` the loop built."""

import types

from pbp_drake.commands import task_runs


def run_loop(monkeypatch, resolved, choices, on_build):
    built, choices = [], iter(choices)
    monkeypatch.setattr(task_runs, "build_diagram", lambda resolved, meshcat, hand_trail:
                        built.append(on_build(resolved)))
    monkeypatch.setattr(task_runs, "run_task_once", lambda *args: (
        types.SimpleNamespace(success=True), types.SimpleNamespace(choice=next(choices))))
    for name in ("page_console", "delete_operator", "end_page"):
        monkeypatch.setattr(task_runs, name, lambda *args: types.SimpleNamespace(
            set_choices=lambda choices: None))
    task_runs.run_task_loop(types.SimpleNamespace(start_on_connect=True, hand_trail=False),
                            resolved, None, page=object())
    return built
