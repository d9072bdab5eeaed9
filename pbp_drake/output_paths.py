"""Checks of the command line's output paths (`--record`, `--log`, `--output`, `--figure`),
made before anything is built or simulated: a path that cannot be written is a user error
(`OutputPathError`, exit 2), not a lost run. And the replay a `--record` writes
(`mark_replay`)."""

import base64
import html as html_text
import os
import pathlib
import re

import msgpack
import numpy as np

from pbp_drake.builder.time_series import time_series_header
from pbp_drake.core.dmp.primitive import PRIMITIVE_FORMAT
from pbp_drake.scenarios import ScenarioError
from pbp_drake.scenarios.bounds import is_special_file
from pbp_drake.systems.visualizers.point_scene_visualizer import LEGEND as SCENE_2D_LEGEND

# Written into every replay just after its doctype: an existing file that holds it is a
# replay of a previous `pbp-drake run --record`, and may be overwritten without --force.
REPLAY_MARKER = "<!-- pbp-drake replay (pbp-drake run --record) -->"
_MARKER_WINDOW = 4096  # bytes read from the top of an existing file to find the marker

# Meshcat's StaticHtml makes its viewer on this line, then decodes its commands, the
# recording last; loading the recording plays it at once.
_VIEWER_LINE = re.compile(r'^[ \t]*var viewer = new MeshCat\.Viewer\(.*\);[ \t]*$', re.M)
# Put just after that line: the recording, once loaded (its tracks then act on the scene),
# is paused and shown at 0 s, so that the replay waits for its viewer.
PAUSED_AT_START = """
    // pbp-drake: the replay starts paused at 0 s (Meshcat would play it once loaded).
    (function () {
      const animator = viewer.animator;
      const load = animator.load.bind(animator);
      animator.load = function (animations, options) {
        load(animations, options);
        animator.pause();
        animator.seek(0);
      };
    })();"""
REPLAY_HINT_ID = "pbp-replay-hint"
LEGEND_ID = "pbp-legend"
_REPLAY_HINT = ("The replay starts paused: Open Controls, then Animations, default, play "
                "(or drag its time).")
# Meshcat's commands, each a base64 msgpack payload; a payload's paths are plain bytes in it.
_PAYLOAD = re.compile(r'fetch\("data:application/octet-binary;base64,([^"]+)"\)')
# A 2-D scene's robot (point_scene_visualizer): the replays that get SCENE_2D_LEGEND.
_SCENE_2D_ROBOT = b"/pbp/robot"


class OutputPathError(ScenarioError):
    """An output path that cannot, or may not, be written."""


def recorded_replay(meshcat):
    """Ends `meshcat`'s recording and returns its replay page as `pbp-drake run --record`
    saves it (`mark_replay` of Meshcat's StaticHtml with the recording published)."""
    meshcat.StopRecording()
    meshcat.PublishRecording()
    return mark_replay(meshcat.StaticHtml())


def mark_replay(html):
    """The replay `html` (Meshcat's StaticHtml) as `pbp-drake run --record` saves it: with
    REPLAY_MARKER; paused at 0 s (a page that loads slowly would miss a short run), with a
    line saying how to play it, when it has Meshcat's viewer line; and, for a 2-D scene, a
    key of its colours (SCENE_2D_LEGEND: Meshcat has no text)."""
    viewer_line = _VIEWER_LINE.search(html)
    if viewer_line:
        html = html[:viewer_line.end()] + PAUSED_AT_START + html[viewer_line.end():]
    notes = []
    if any(_SCENE_2D_ROBOT in base64.b64decode(payload) for payload in _PAYLOAD.findall(html)):
        notes.append(legend_html(SCENE_2D_LEGEND))
    if viewer_line:
        notes.append(f'<div id="{REPLAY_HINT_ID}" style="position: fixed; right: 8px; '
                     'bottom: 8px; padding: 2px 6px; font: 12px sans-serif; '
                     f'background: rgba(255, 255, 255, 0.8);">{_REPLAY_HINT}</div>')
    if notes:
        body_end = html.rfind("</body>")
        if body_end < 0:
            body_end = len(html)
        html = html[:body_end] + "\n".join(notes) + "\n" + html[body_end:]
    head, newline, rest = html.partition("\n")
    if head.lower().startswith("<!doctype") and newline:
        return f"{head}\n{REPLAY_MARKER}\n{rest}"
    return f"{REPLAY_MARKER}\n{html}"


def legend_html(entries):
    """A key in the page's bottom-left corner: one coloured swatch and its name for each
    `(name, Rgba)` of `entries`."""
    rows = "".join(
        f'<div><span style="display: inline-block; width: 12px; height: 12px; '
        f'margin-right: 6px; vertical-align: middle; background: {_css_colour(colour)};">'
        f'</span>{html_text.escape(name)}</div>' for name, colour in entries)
    return (f'<div id="{LEGEND_ID}" style="position: fixed; left: 8px; bottom: 8px; '
            'padding: 4px 8px; font: 12px/18px sans-serif; '
            f'background: rgba(255, 255, 255, 0.8);">{rows}</div>')


def _css_colour(colour):
    red, green, blue = (round(255 * value) for value in (colour.r(), colour.g(), colour.b()))
    return f"rgba({red}, {green}, {blue}, {colour.a():g})"


def replay_track(html, path, track):
    """`(times (T,), values (T, ...))` of the animation track `track` (e.g. ".position") of
    the Meshcat `path` in a replay's recording, times in seconds; ValueError when the page
    records none."""
    for payload in _PAYLOAD.findall(html):
        data = base64.b64decode(payload)
        if b"set_animation" not in data:
            continue
        command = msgpack.unpackb(data, raw=False, strict_map_key=False)
        for animation in command.get("animations", []):
            if animation.get("path") != path:
                continue
            clip = animation["clip"]
            for recorded in clip["tracks"]:
                if recorded["name"] == track:
                    keys = recorded["keys"]
                    return (np.array([key["time"] / clip["fps"] for key in keys], float),
                            np.array([key["value"] for key in keys], float))
    raise ValueError(f"the replay records no {track} of {path}")


def is_replay(path):
    """Whether the file at `path` is a replay written by `pbp-drake run --record`."""
    return _head_holds(path, REPLAY_MARKER.encode())


def _head_holds(path, marker):
    """Whether the first bytes of the file at `path` hold `marker`."""
    try:
        with open(path, "rb") as stream:
            head = stream.read(_MARKER_WINDOW)
    except OSError:
        return False
    return marker in head


def check_record_path(path, force=False):
    """Raises OutputPathError unless `path` can take a replay: a writable file, an existing
    one a previous replay unless `force`."""
    _check_output_file(path, "--record", "replay.html", is_replay, "a replay", force)


def check_log_path(path, force=False):
    """Raises OutputPathError unless `path` can take a run's per-tick CSV: a writable file,
    an existing one a time series (the trial CSV's header) unless `force`."""
    _check_output_file(path, "--log", "run.csv", _is_time_series, "a time series", force)


def check_primitive_path(path, force=False):
    """Raises OutputPathError unless `path` can take a taught primitive (`teach --output`):
    a writable file, an existing one a primitive unless `force`."""
    _check_output_file(path, "--output", "primitive.json", _is_primitive, "a primitive", force)


def check_figure_path(path):
    """Raises OutputPathError unless `path` can take a figure (`--figure`): a writable .png,
    .svg or .pdf file (an existing one is drawn over)."""
    file = pathlib.Path(path)
    if file.suffix.lower() not in (".png", ".svg", ".pdf"):
        raise OutputPathError(f"--figure {file}: a figure is a .png, .svg or .pdf file")
    _check_output_file(file, "--figure", "primitive.png", None, "a figure", force=True)


def check_drawing_path(path):
    """Raises OutputPathError unless `path` can take a drawing (`pbp-drake draw --output`):
    a writable file (an existing one is drawn over), not a device or a pipe (a pipe's open
    waits for a reader; `-` is standard output)."""
    _check_output_file(path, "--output", "diagram.svg", None, "a drawing", force=True)
    if is_special_file(path):
        raise OutputPathError(f"--output {path}: is not a regular file (a device or a pipe); "
                              "give a file, or - for standard output")


def _is_primitive(path):  # as `pbp-drake teach` writes it (json.dumps' separators)
    return _head_holds(path, f'"format": "{PRIMITIVE_FORMAT}"'.encode())


def _check_output_file(path, flag, example, is_ours, kind, force):
    """`path` is not a folder (`example`: a file in it), it or its folder is writable, and
    a file there is one `is_ours` recognises (`kind`) or `force` is set."""
    if not os.fspath(path):  # pathlib would read it as ".", the current folder
        raise OutputPathError(f"{flag}: the path is empty; give a file, e.g. {example}")
    file = pathlib.Path(path)
    if file.is_dir():
        raise OutputPathError(f"{flag} {file}: is a folder; give a file, e.g. "
                              f"{file / example}")
    if (dangling := dangling_link(file)) is not None:  # was "the file exists"
        raise OutputPathError(f"{flag} {file}: is {dangling}; give another path")
    if is_special_file(file) and not force:
        raise OutputPathError(f"{flag} {file}: is not a regular file (a device or a pipe); "
                              f"add --force to write to it")
    if file.exists() or file.is_symlink():
        if not force and not is_ours(file):
            raise OutputPathError(f"{flag} {file}: the file exists and is not {kind} "
                                  f"written by pbp-drake; add --force to overwrite it")
        if not os.access(file, os.W_OK):
            raise OutputPathError(f"{flag} {file}: the file is not writable")
        return
    _check_can_create(file.parent, f"{flag} {file}")


def dangling_link(path):
    """How `path` is a symbolic link to nothing (its target is missing, or links loop), in
    words, or None when it is not one."""
    path = pathlib.Path(path)
    if path.is_symlink() and not path.exists():
        return (f"a symbolic link to nothing (its target {os.readlink(path)} is missing, or "
                "the links loop)")
    return None


def _is_time_series(path):
    try:
        with open(path, newline="") as stream:
            head = stream.readline(_MARKER_WINDOW)
    except (OSError, UnicodeDecodeError):
        return False
    # The reach tasks' (with or without in_collision) and the grasping task's.
    return head in (time_series_header(False), time_series_header(True),
                    time_series_header(False, has_grasp=True))


def check_output_folder(path):
    """Raises OutputPathError unless `path` is a writable folder or can be made one."""
    if not os.fspath(path):  # pathlib would read it as ".", the current folder
        raise OutputPathError("--output: the path is empty; give a folder for the results")
    output = pathlib.Path(path)
    if (dangling := dangling_link(output)) is not None:  # its mkdir failed: "file exists"
        raise OutputPathError(f"--output {output}: is {dangling}; give another folder")
    if output.exists() and not output.is_dir():
        raise OutputPathError(f"--output {output}: is a file, not a folder; give a folder "
                              f"for the results")
    if output.is_dir():
        if not os.access(output, os.W_OK | os.X_OK):
            raise OutputPathError(f"--output {output}: the folder is not writable")
        return
    _check_can_create(output, f"--output {output}")


def same_file(first, second):
    """Whether the paths `first` and `second` name one file (existing or not)."""
    first, second = pathlib.Path(first), pathlib.Path(second)
    if first.exists() and second.exists():
        return os.path.samefile(first, second)
    return os.path.realpath(first) == os.path.realpath(second)


def _check_can_create(folder, what):
    """Raises OutputPathError unless `folder`'s nearest existing ancestor is a writable
    folder."""
    folder = pathlib.Path(os.path.abspath(folder))
    ancestor = folder
    while not ancestor.exists() and ancestor.parent != ancestor:
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise OutputPathError(f"{what}: {ancestor} is a file, so its folder cannot be made")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        where = "its folder" if ancestor == folder else f"{ancestor}"
        raise OutputPathError(f"{what}: {where} is not writable")
