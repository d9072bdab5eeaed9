"""The operator's console: what a person at the Meshcat page sees of a run and can do: the
words (`text`), the buttons, sliders and lines (`Console`), a live run feeding them
(`LiveRun`), a session's pages (`questionnaire`) and the page's front (`PageFront`).

A minimal loop (the thread that made `meshcat`; with `front = PageFront(meshcat.port())`,
open `front.url` and pass `panel=front` to the Console)::

    console = Console(meshcat, choices=("stop", "next"))
    console.show_title(method_name(scenario.method))
    live = LiveRun(diagram, scenario.duration, console)
    result = run_task(resolved, diagram=diagram, realtime_rate=1.0, advance=live.advance)
    console.show_result(result_text(result.success, result.task_time,
                                    stopped=live.choice is not None))
    choice = live.choice or console.wait_for_choice()
"""

from pbp_drake.console.camera import CAMERAS, RobotCamera, behind_head_view
from pbp_drake.console.front import PageFront
from pbp_drake.console.live import LiveRun, Progress
from pbp_drake.console.page import ALPHA_SLIDER, CHOICE_BUTTONS, RATE_SLIDER, Console
from pbp_drake.console.text import (
    method_name, progress_text, result_text, status_text, time_left)

__all__ = ["ALPHA_SLIDER", "CAMERAS", "CHOICE_BUTTONS", "RATE_SLIDER", "Console", "LiveRun",
           "PageFront", "Progress", "RobotCamera", "behind_head_view", "method_name",
           "progress_text", "result_text", "status_text", "time_left"]
