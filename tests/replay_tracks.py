"""What a Meshcat replay (`Meshcat.StaticHtml()`, the file `pbp-drake run --record` writes)
holds: its commands, decoded, and the animation tracks a replay plays.

The page carries each command as a msgpack payload in `fetch("data:...;base64,...")`; the
recording is one `set_animation` command whose clips key their tracks by frame.
"""

import base64
import re

import msgpack
import numpy as np
from pydrake.systems.analysis import Simulator

_PAYLOAD = re.compile(r'fetch\("data:application/octet-binary;base64,([^"]+)"\)')


def commands(html):
    """The Meshcat commands of the page, in order, as dicts."""
    return [msgpack.unpackb(base64.b64decode(payload), raw=False, strict_map_key=False)
            for payload in _PAYLOAD.findall(html)]


def animation_tracks(html):
    """`{(path, track): (times (T,), values (T, ...))}` of the recording, e.g.
    `("/pbp/robot", ".position")`; times in seconds."""
    tracks = {}
    for command in commands(html):
        if command.get("type") != "set_animation":
            continue
        for animation in command["animations"]:
            clip = animation["clip"]
            for track in clip["tracks"]:
                keys = track["keys"]
                tracks[animation["path"], track["name"]] = (
                    np.array([key["time"] / clip["fps"] for key in keys]),
                    np.array([key["value"] for key in keys]))
    return tracks


def value_at(tracks, path, track, time):
    """The value of `track` of `path` at its key nearest `time`."""
    times, values = tracks[path, track]
    return values[int(np.argmin(np.abs(times - time)))]


def held_at(tracks, path, track, time):
    """The value of `track` of `path` at `time` as a replay shows a discrete track (e.g.
    `.visible`): its last key at or before `time` (its first before that)."""
    times, values = tracks[path, track]
    return values[max(0, int(np.searchsorted(times, time + 1e-9, side="right")) - 1)]


def recorded_page(meshcat, run):
    """The page (`StaticHtml`) of a recording at 30 frames a second of `run()` in
    `meshcat`."""
    meshcat.StartRecording(frames_per_second=30.0)
    run()
    meshcat.StopRecording()
    meshcat.PublishRecording()
    return meshcat.StaticHtml()


def recorded(meshcat, diagram, duration):
    """The animation tracks of a recording of `duration` seconds of `diagram` in `meshcat`."""
    return animation_tracks(recorded_page(
        meshcat, lambda: Simulator(diagram).AdvanceTo(duration)))
