"""The operator's console: what a person at the Meshcat page sees of a run and can do.

Three layers, each usable alone, and a session's pages:

- `pbp_drake.console.text`: the words, as pure functions of numbers (`method_name`,
  `status_text` "time left 41 s · 2 target switches · intervention 31 %", `result_text`
  "success in 14.2 s" / "failed: time limit" / "stopped at 9.0 s", `progress_text`).
- `Console` (`pbp_drake.console.page`): the page's controls. Choice buttons (Stop,
  Restart, Next scene), optional alpha and real-time-rate sliders, and four lines of
  text (title, status, result, notice) in the page front's panel, or shown as button
  labels on a bare Meshcat, which has no text.
  `choice()` polls, `wait_for_choice()` blocks.
- `LiveRun` (`pbp_drake.console.live`): a running simulation feeding a Console, a
  `RobotCamera` and the terminal's `Progress`; its `advance` is the `advance` argument of
  `pbp_drake.builder.run_task` (and `run_task_streamed`, `simulate`).
- `pbp_drake.console.questionnaire`: a user-study session's pages (Start, the two
  questions, Next) and `FixedAnswers` for unattended sessions.
- `PageFront` (`pbp_drake.console.front`): the page behind a front of our own, which lets
  in only the holder of the run's secret URL, relays Meshcat to a slow page at the rate it
  draws, and shows the console's lines in a panel of its own (`Console(..., panel=front)`).

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
