"""The page of `pbp-drake run` and `session`: its flags, the private Meshcat behind it, the
wait for a browser before a run and the result kept after it."""

import logging
import pathlib
import sys
import time

from pydrake.geometry import Meshcat, MeshcatParams

from pbp_drake.cli_types import port, token, wait_seconds
from pbp_drake.console import Console
from pbp_drake.console.front import ENDED_NOTICE, PageFront
from pbp_drake.console.live import closed_for
from pbp_drake.output_paths import recorded_replay
from pbp_drake.scenarios import ScenarioError
from pbp_drake.studies.atomic_files import write_atomically

#: The choices in the page while a task runs.
RUN_CHOICES = ("stop", "restart", "next")
#: After a single task's run, while the page is kept.
AFTER_RUN_CHOICES = ("restart", "next", "close")
# Why a keyboard or gamepad run stops when no browser opens its page.
PERSON_NEEDS_PAGE = ("the keyboard and gamepad are read in the page, so nothing was run or "
                     "recorded")
KEEP_PAGE_SECONDS = 600.0
WAIT_FOR_BROWSER_SECONDS = 15.0
# A page that reloads has no connection for a moment (the old one closed, the new one not yet
# open, the script being loaded): the kept page ends once none has been there this long.
RELOAD_SECONDS = 5.0


def add_page_flags(parser):
    """The page's flags, in their own group of `parser`'s help."""
    page = parser.add_argument_group("the page")
    page.add_argument("--port", type=port, default=0,
                      help="the page's port, 0..65535 (default 0: a free one); one in use "
                      "is refused before anything is built")
    page.add_argument("--token", type=token,
                      help="the page's secret (16 to 128 letters, digits, '-' or '_'; "
                      "default: a random one): only a browser that opens the printed URL, "
                      "which holds it, gets the page and can drive")
    page.add_argument("--start-on-connect", action="store_true",
                      help="keyboard and gamepad runs: start the task as soon as the page "
                      "connects, as a script wants, instead of at the page's Start button")
    page.add_argument("--keep-page", type=wait_seconds, default=KEEP_PAGE_SECONDS,
                      metavar="SECONDS",
                      help="after the run, keep the page with its result served until it "
                      "is closed, its Close button is pressed, or this many seconds pass "
                      f"(default {KEEP_PAGE_SECONDS:g})")
    page.add_argument("--wait-for-browser", type=wait_seconds, default=WAIT_FOR_BROWSER_SECONDS,
                      metavar="SECONDS", help="before starting, wait this long for a "
                      f"browser to open the page (default {WAIT_FOR_BROWSER_SECONDS:g}); a "
                      "keyboard or gamepad run that no browser joins in time stops with exit "
                      "2, having run and recorded nothing")


def page_flags_given(args):
    """The page's flags that `args` sets to other than their defaults."""
    given = {"--port": args.port != 0, "--token": args.token is not None,
             "--start-on-connect": args.start_on_connect,
             "--keep-page": args.keep_page != KEEP_PAGE_SECONDS,
             "--wait-for-browser": args.wait_for_browser != WAIT_FOR_BROWSER_SECONDS}
    return [flag for flag, set_ in given.items() if set_]


def open_page(listening, args):
    """`(meshcat, page)`: a Meshcat on a random free localhost port that nobody is told of
    (Drake's `port=None` takes the first free one from 7000, easy to guess) and, with
    `listening` (the page's bound socket), the page front people open; else page None."""
    drake_log = logging.getLogger("drake")
    level = drake_log.level
    drake_log.setLevel(logging.WARNING)  # not Drake's line announcing the private URL
    try:
        meshcat = Meshcat(MeshcatParams(host="localhost", port=0))
    finally:
        drake_log.setLevel(level)
    if listening is None:
        return meshcat, None
    page = PageFront(meshcat.port(), listening, token=args.token)
    print(f"Meshcat: {page.url}", flush=True)
    return meshcat, page


def page_console(meshcat, page, args, alpha, choices=RUN_CHOICES):
    """The page's console: its lines in the front's panel, the choices, the alpha slider
    (`alpha`, None for none) and the real-time rate slider."""
    return Console(meshcat, choices, alpha=alpha, realtime_rate=args.realtime_rate,
                   panel=page)


def keep_page(args, page, console, choices):
    """After a run: the result stays served until the person closes the page (no browser on
    it for `RELOAD_SECONDS`: a reload is not a close), presses one of `choices` or Enter in
    a terminal, or --keep-page seconds pass; the choice, or None."""
    closed = closed_for(page.pages, min(RELOAD_SECONDS, args.keep_page))
    while page.pages() == 0:
        if closed():
            return None
        time.sleep(0.05)
    console.set_choices(choices)
    words = {"restart": "Restart runs the scene again", "next": "Next scene the next seed"}
    others = [words[choice] for choice in choices if choice in words]
    print("The page keeps the result until it is closed" + (": " + ", ".join(others)
                                                           if others else "")
          + f"; Close, Enter or closing the page ends the command (at the latest in "
          f"{args.keep_page:g} s).", flush=True)
    return console.wait_for_choice(stdin=terminal(), timeout=args.keep_page, until=closed)


def end_page(page, console, text=ENDED_NOTICE):
    """The command is done: the page says so, its buttons and sliders gone (the operator's
    are the caller's: `task_runs.delete_operator`)."""
    if console is not None:
        console.remove_controls()
    page.end(text)


def wait_for_browser(page, seconds, needed=None):
    """Waits up to `seconds` for a browser on the page; a run that cannot go on without one
    (`needed` says why) stops with exit 2 (ScenarioError) before anything runs."""
    deadline = time.monotonic() + seconds
    while page.pages() == 0 and time.monotonic() < deadline:
        time.sleep(0.05)
    if needed is not None and page.pages() == 0:
        raise ScenarioError(f"no browser opened {page.url} within {seconds:g} s "
                            f"(--wait-for-browser): {needed}")


def terminal():
    """stdin when it is a terminal, where Enter stops a run's wait; else None."""
    return sys.stdin if sys.stdin.isatty() else None


def save_recording(meshcat, path):
    record = pathlib.Path(path)
    write_atomically(record, recorded_replay(meshcat))
    print(f"Replay saved to {record}")
