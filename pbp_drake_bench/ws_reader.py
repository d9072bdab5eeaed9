"""A Meshcat client that reads everything sent, for the bench's runs with a client connected:
`python pbp_drake_bench/ws_reader.py ws://localhost:PORT` (this file as a script, which
imports websockets alone) connects to a Meshcat's websocket,
reads every message, counting messages and bytes, until the connection closes (or a DONE
mark arrives, or SIGTERM), and then prints its totals to stdout as one JSON line.

It runs in a process of its own, as a browser would (it must not share the simulation's
Python thread, and Meshcat must be called from the thread that made it). The process
being measured delimits what it wants counted with marks (`send_mark`: a property set on
a path holding `MARK` and the mark's name, sent in order with everything else): at each
the reader records its totals so far, the mark's own message not counted. A `DONE` mark
ends the reading. Reading stays cheap (a byte search per message, no decoding), so the
reader keeps up on a second core.

`MeshcatReader` starts the process, waits on Meshcat's own count of connections (a state,
not a sleep), and reads back its totals."""

import json
import os
import signal
import subprocess
import sys
import time

from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

MARK = "pbp_bench_mark"
DONE = "done"
_TOKEN = MARK.encode()


def read(url):
    """Reads `url` until it closes or a DONE mark: `{"bytes", "messages", "marks": {name:
    {"bytes", "messages"}}, "closed_by"}`, counting every message but the marks."""
    totals = {"bytes": 0, "messages": 0, "marks": {}, "closed_by": "server"}

    def stop(signum, frame):
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, stop)
    # No proxy, no compression (the bytes counted are those on the wire), no size limit
    # (a scene's meshes come in one message).
    with connect(url, proxy=None, compression=None, max_size=None, ping_interval=None,
                 open_timeout=30) as websocket:
        try:
            while True:
                message = websocket.recv()
                if isinstance(message, str):
                    message = message.encode()
                at = message.find(_TOKEN)
                if at >= 0:
                    name = _mark_name(message, at)
                    totals["marks"][name] = {"bytes": totals["bytes"],
                                             "messages": totals["messages"]}
                    if name == DONE:
                        totals["closed_by"] = "done mark"
                        break
                    continue
                totals["bytes"] += len(message)
                totals["messages"] += 1
        except ConnectionClosed:
            pass
        except KeyboardInterrupt:
            totals["closed_by"] = "signal"
    return totals


def _mark_name(message, at):
    # The path is "/pbp_bench_mark/<name>" in the msgpack'd message: the name ends at the
    # first byte that is not a word character.
    start = at + len(_TOKEN) + 1
    end = start
    while end < len(message) and (chr(message[end]).isalnum() or message[end] in b"_-"):
        end += 1
    return message[start:end].decode()


def send_mark(meshcat, name):
    """Sends the mark `name` (letters, digits, _ and -) through `meshcat` to its clients."""
    meshcat.SetProperty(f"/{MARK}/{name}", "visible", False)


class MeshcatReader:
    """A `read` process on `meshcat`'s websocket, connected when constructed: `span(first,
    last)` is what it read between two marks, after `finish()`."""

    def __init__(self, meshcat, timeout=30.0):
        self._meshcat = meshcat
        before = meshcat.GetNumActiveConnections()
        url = f"ws://localhost:{meshcat.port()}"
        self._process = subprocess.Popen(
            # This file as a script: the reader imports websockets alone, not pbp_drake.
            [sys.executable, os.path.abspath(__file__), url], stdout=subprocess.PIPE,
            text=True)
        deadline = time.monotonic() + timeout
        while meshcat.GetNumActiveConnections() <= before:
            if self._process.poll() is not None or time.monotonic() > deadline:
                self._process.kill()
                raise RuntimeError(f"the websocket reader did not connect to {url} within "
                                   f"{timeout:g} s (exit code {self._process.poll()})")
            time.sleep(0.005)
        self.totals = None

    def finish(self, timeout=600.0):
        """Sends the DONE mark and waits (up to `timeout` s) for the reader to drain what
        Meshcat sent before it and print its totals; returns them."""
        send_mark(self._meshcat, DONE)
        try:
            out, _ = self._process.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            self._process.terminate()
            out, _ = self._process.communicate(timeout=30)
        lines = out.strip().splitlines()
        self.totals = json.loads(lines[-1]) if lines else None
        return self.totals

    def span(self, first, last):
        """`(bytes, messages)` read between the marks `first` and `last`."""
        marks = self.totals["marks"]
        return (marks[last]["bytes"] - marks[first]["bytes"],
                marks[last]["messages"] - marks[first]["messages"])


if __name__ == "__main__":
    print(json.dumps(read(sys.argv[1])), flush=True)
