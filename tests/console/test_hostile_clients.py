"""Hostile clients against the page front and its Meshcat, in one process: an authorised page
sending bytes Meshcat's parser dies on, programs going straight to Meshcat's port, pages that
close as they connect, request targets without `/`. The person's page (a raw authorised
websocket here) keeps pressing its key through all of it, and Meshcat lives on.

Meshcat is used only from the test's thread; the clients are plain sockets and websockets.
"""

import gc
import socket
import subprocess
import sys
import threading
import time

import msgpack
import pytest
from foreign_page import ForeignPage
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from pbp_drake.console import meshcat_door
from pbp_drake.console.front import ACK, BAD_FRAME_CLOSE, PageFront
from pbp_drake.console.page_messages import MAX_MESSAGE
from pbp_drake.systems.operators.browser_guard import BrowserGuard

KEY = "Left (←)"
# Frames Drake's Meshcat dies on when they reach it (its websocket thread ends, and the run).
DEADLY = {"0xc1": b"\xc1", "a truncated map": b"\x82\xa4type\xa6button\xa4na",
          "an oversized array header": b"\xdd\xff\xff\xff\xff",
          "an oversized str header": b"\x81\xa4type\xdb\xff\xff\xff\xff",
          "an oversized bin header": b"\xc6\xff\xff\xff\xff"}


@pytest.fixture(autouse=True)
def _meshcats_die_on_this_thread():
    yield
    gc.collect()  # see test_front.py: a Meshcat must die on the thread that made it


@pytest.fixture
def front(meshcat):
    meshcat.AddButton(KEY)
    with PageFront(meshcat.port(), host="localhost") as front:
        yield front


def _until(condition, seconds=5.0):
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.01)
    return True


def _page(front):
    return connect(f"ws://localhost:{front.port}/?token={front.token}",
                   origin=f"http://localhost:{front.port}", open_timeout=5.0,
                   max_size=None)


def _press(page, meshcat):
    """The person presses the key: it counts once, Meshcat alive to count it."""
    before = meshcat.GetButtonClicks(KEY)
    page.send(msgpack.packb({"type": "button", "name": KEY}))
    assert _until(lambda: meshcat.GetButtonClicks(KEY) == before + 1)


def _closed(page, seconds=5.0):
    """The close the front sent `page`, once it has: (code, reason)."""
    deadline = time.monotonic() + seconds
    try:
        while time.monotonic() < deadline:
            page.recv(timeout=max(0.01, deadline - time.monotonic()))
    except (ConnectionClosed, TimeoutError):
        pass
    return page.protocol.close_rcvd.code, page.protocol.close_rcvd.reason


@pytest.mark.slow
@pytest.mark.parametrize("frame", DEADLY.values(), ids=DEADLY.keys())
def test_a_deadly_frame_closes_its_page_with_a_reason_and_the_person_drives_on(
        meshcat, front, frame):
    with _page(front) as person:
        _press(person, meshcat)
        with _page(front) as hostile:
            assert _until(lambda: front.pages() == 2)
            hostile.send(frame)
            code, reason = _closed(hostile)
            assert front.pages_heard() == 1  # a refused frame makes no second person
        assert code == BAD_FRAME_CLOSE and reason.startswith("bad message: ")
        assert _until(lambda: front.pages() == 1 and meshcat.GetNumActiveConnections() == 1)
        _press(person, meshcat)


@pytest.mark.slow
def test_unknown_messages_and_oversized_frames_close_their_page(meshcat, front):
    with _page(front) as person:
        for frame, expected in [(msgpack.packb({"type": "set_transform", "path": "/"}),
                                 BAD_FRAME_CLOSE), ("hello", BAD_FRAME_CLOSE),
                                (b"\x90" * (MAX_MESSAGE + 1), 1009)]:
            with _page(front) as hostile:
                hostile.send(frame)
                assert _closed(hostile)[0] == expected
        _press(person, meshcat)
        assert _until(lambda: front.pages() == 1 and meshcat.GetNumActiveConnections() == 1)


@pytest.mark.slow
def test_meshcats_port_lets_in_nobody_but_the_front(meshcat, front):
    assert front.door_shut
    with _page(front) as person:
        _press(person, meshcat)
        for attempt in range(3):  # plain, and from the front's own address and a port
            stranger = socket.socket()
            if attempt:
                stranger.bind(("127.0.0.1", 0))
            stranger.settimeout(1.0)
            with pytest.raises(TimeoutError):  # no answer: the request is dropped
                stranger.connect(("localhost", meshcat.port()))
            stranger.close()
        assert meshcat.GetNumActiveConnections() == 1
        _press(person, meshcat)
    front.close()  # and after the front, shut still
    with pytest.raises(TimeoutError):
        socket.create_connection(("localhost", meshcat.port()), timeout=1.0)


def _handshake(front, read_answer):
    raw = socket.create_connection(("localhost", front.port), timeout=5.0)
    raw.sendall(f"GET /?token={front.token} HTTP/1.1\r\nHost: localhost:{front.port}\r\n"
                "Upgrade: websocket\r\nConnection: Upgrade\r\n"
                "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
                f"Origin: http://localhost:{front.port}\r\n\r\n".encode())
    if read_answer:
        assert raw.recv(12) == b"HTTP/1.1 101"
    raw.close()


@pytest.mark.slow
def test_pages_that_close_as_they_connect_leave_no_connection_to_meshcat(
        meshcat, front, caplog):
    announced = []
    guard = BrowserGuard(meshcat, announce=announced.append)

    def quick_pages():
        for i in range(20):
            _handshake(front, read_answer=i % 2 == 0)
            with _page(front):
                pass

    with _page(front) as person:
        person.send(ACK)
        assert _until(lambda: front.pages_heard() == 1)
        closer = threading.Thread(target=quick_pages)
        closer.start()
        while closer.is_alive():  # the operator's ticks meanwhile: never a pause
            guard.wait_while_shared()
        assert guard.pauses == 0 and not announced, announced
        assert _until(lambda: front.pages() == 1 and meshcat.GetNumActiveConnections() == 1)
        _press(person, meshcat)
    assert _until(lambda: front.pages() == 0 and meshcat.GetNumActiveConnections() == 0)
    assert not [r for r in caplog.records if r.levelname in ("ERROR", "CRITICAL")]


@pytest.mark.slow
@pytest.mark.parametrize("target", ["etc/passwd", "?token={token}", "*",
                                    "http://localhost:{port}/?token={token}"])
def test_a_target_without_a_leading_slash_gets_400(front, target):
    target = target.format(token=front.token, port=front.port)
    raw = socket.create_connection(("localhost", front.port), timeout=5.0)
    raw.sendall(f"GET {target} HTTP/1.1\r\nHost: localhost:{front.port}\r\n"
                f"Cookie: pbp_drake_token={front.token}\r\n\r\n".encode())
    answer = b""
    while chunk := raw.recv(4096):
        answer += chunk
    raw.close()
    assert answer.startswith(b"HTTP/1.1 400 ") and b"MeshCat" not in answer


@pytest.mark.slow
def test_where_the_door_stays_open_an_intruder_is_ignored_not_obeyed(meshcat, monkeypatch,
                                                                     capsys):
    monkeypatch.setattr(meshcat_door, "_listeners", lambda port: ([], "no filter here"))
    meshcat.AddButton(KEY)
    announced = []
    guard = BrowserGuard(meshcat, announce=announced.append)
    with PageFront(meshcat.port()) as front, _page(front) as person:
        assert not front.door_shut
        assert "Meshcat's port stays open to other programs" in capsys.readouterr().err
        _press(person, meshcat)
        assert not guard.wait_while_shared()
        intruder = ForeignPage(meshcat.port())
        assert _until(lambda: meshcat.GetNumActiveConnections() == 2)
        started = time.monotonic()
        assert guard.wait_while_shared() and guard.wait_while_shared()  # input dropped
        assert time.monotonic() - started < 0.5 and guard.pauses == 0  # not paused
        assert len(announced) == 1 and "did not open" in announced[0]
        intruder.close()
        assert _until(lambda: meshcat.GetNumActiveConnections() == 1)
        assert not guard.wait_while_shared()
        assert "count again" in announced[-1]


@pytest.mark.slow
def test_a_second_page_pauses_once_it_speaks(meshcat, front):
    announced = []
    guard = BrowserGuard(meshcat, announce=announced.append, poll_period=0.01)
    with _page(front) as person:
        person.send(ACK)  # as our page answers its first batch
        assert _until(lambda: front.pages_heard() == 1)
        assert not guard.wait_while_shared()
        with _page(front) as second:
            # Admitted but silent (it cannot press a key): the person drives on.
            assert _until(lambda: front.pages() == 2)
            assert not guard.wait_while_shared() and front.pages_heard() == 1
            second.send(ACK)
            assert _until(lambda: front.pages_heard() == 2)
            # The second page goes once the pause is announced.
            closer = threading.Thread(target=lambda: _until(lambda: announced, 10.0)
                                      and second.close())
            closer.start()
            assert guard.wait_while_shared() and guard.pauses == 1
            assert announced[0].startswith("Paused: 2 browsers are connected")
            closer.join()
        assert _until(lambda: front.pages_heard() == 1)


# Out of file descriptors: the front's accepts fail while clients of this same process hold
# every descriptor; asyncio retries each second. Then the clients go and the page is served.
OUT_OF_DESCRIPTORS = """
import os, resource, socket, sys, time, urllib.request
from pydrake.geometry import Meshcat, MeshcatParams
from pbp_drake.console.front import PageFront
meshcat = Meshcat(MeshcatParams(host="localhost", port=0))
front = PageFront(meshcat.port())
open_now = len(os.listdir("/proc/self/fd"))
resource.setrlimit(resource.RLIMIT_NOFILE,
                   (open_now + 40, resource.getrlimit(resource.RLIMIT_NOFILE)[1]))
held = []
try:
    while True:
        held.append(socket.create_connection(("localhost", front.port), timeout=5))
except OSError:
    pass
failures, deadline = set(), time.monotonic() + 20
while len(failures) < 3 and time.monotonic() < deadline:  # three accepts refused
    if front._accept_errors is not None:
        failures.add(front._accept_errors)
    time.sleep(0.05)
for client in held:
    client.close()
url = f"http://localhost:{front.port}/pbp/state?token={front.token}"
with urllib.request.urlopen(url, timeout=10) as reply:
    print("refused", len(failures), "then served", reply.status)
front.close()
"""


@pytest.mark.slow  # a Meshcat in a process, out of descriptors for three seconds
@pytest.mark.timeout(90)
def test_out_of_descriptors_is_one_line_and_the_page_is_served_after(repo):
    done = subprocess.run([sys.executable, "-c", OUT_OF_DESCRIPTORS], cwd=repo, timeout=80,
                          capture_output=True, text=True)
    assert done.stdout.strip() == "refused 3 then served 200", done.stderr
    assert done.stderr.count("the page's port cannot accept connections") == 1, done.stderr
    assert "Traceback" not in done.stderr, done.stderr
