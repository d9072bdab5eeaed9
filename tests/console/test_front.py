"""The page front: only the token's holder, from the page's own origin, reaches Meshcat; the
panel's state over HTTP; the relay's queue toward a slow page stays bounded.

Meshcat is used only from the test's thread; the clients are plain sockets and websockets.
"""

import gc
import json
import socket
import time
import urllib.error
import urllib.request

import msgpack
import pytest
from pydrake.geometry import Box, Rgba
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import connect

from pbp_drake.console.front import (
    ACK, AWAY, FRAME, HERE, PageFront, PendingMessages, PortError, bind_page_port, check_token,
    message_key, new_token)


@pytest.fixture(autouse=True)
def _meshcats_die_on_this_thread():
    """Drake aborts the process when a Meshcat is destroyed off the thread that made it. A
    test's Meshcat left in a reference cycle (an exception's traceback holds the test's
    frame) would die in whichever thread next runs the garbage collector, the front's loop
    among them; so the collector runs here, after the Meshcat fixture let go of it."""
    yield
    gc.collect()


@pytest.fixture
def front(meshcat):
    with PageFront(meshcat.port(), host="localhost") as front:
        yield front


def _get(url, cookie=None):
    request = urllib.request.Request(url, headers={"Cookie": cookie} if cookie else {})
    try:
        with urllib.request.urlopen(request, timeout=5.0) as reply:
            return reply.status, reply.headers, reply.read()
    except urllib.error.HTTPError as error:
        return error.code, error.headers, error.read()


def _until(condition, seconds=5.0):
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.01)
    return True


def _websocket(front, query="", origin=None):
    origin = f"http://localhost:{front.port}" if origin is None else origin
    return connect(f"ws://localhost:{front.port}/{query}", origin=origin, open_timeout=5.0)


def _press(button):
    return msgpack.packb({"type": "button", "name": button})


@pytest.mark.slow
def test_http_needs_the_token_then_the_cookie(front):
    base = f"http://localhost:{front.port}/"
    assert _get(base)[0] == 403
    status, _, body = _get(base + "?token=" + new_token())
    assert status == 403 and b"address" in body
    status, headers, body = _get(front.url)
    assert status == 200 and b'id="pbp-console"' in body and b"</body>" in body
    for line in ("title", "status", "result", "notice"):
        assert f'id="pbp-{line}"'.encode() in body
    assert b"do_reconnect = false" in body and b"display: none !important" in body
    cookie = headers["Set-Cookie"]
    assert cookie == f"pbp_drake_token={front.token}; HttpOnly; SameSite=Strict; Path=/"
    status, _, script = _get(base + "meshcat.js", cookie=cookie.split(";")[0])
    assert status == 200 and b"MeshCat" in script
    assert _get(base + "favicon.ico", cookie="pbp_drake_token=" + "x" * 32)[0] == 403


def test_a_file_the_page_did_not_preload_comes_from_meshcat_or_is_not_found(front):
    cookie = f"pbp_drake_token={front.token}"
    status, _, body = _get(f"http://localhost:{front.port}/favicon.ico", cookie)
    assert status == 200 and body.startswith(b"\x00\x00\x01\x00")  # Meshcat's icon
    status, _, body = _get(f"http://localhost:{front.port}/no/such/file", cookie)
    assert (status, body) == (404, b"Not found\n")


@pytest.mark.slow
def test_refused_websockets_never_reach_meshcat(meshcat, front):
    meshcat.AddButton("Left")
    for query, origin in [(f"?token={front.token}", "http://evil.example"), ("", None),
                          (f"?token={new_token()}", None),
                          (f"?token={front.token}", f"http://localhost:{meshcat.port()}")]:
        with pytest.raises(InvalidStatus) as refused:
            _websocket(front, query, origin)
        assert refused.value.response.status_code == 403
    # A raw client that presses at once, without waiting for the answer.
    raw = socket.create_connection(("localhost", front.port), timeout=5.0)
    raw.sendall(f"GET / HTTP/1.1\r\nHost: localhost:{front.port}\r\nUpgrade: websocket\r\n"
                "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                "Sec-WebSocket-Version: 13\r\nOrigin: http://evil.example\r\n\r\n".encode()
                + bytes([0x82, 0x80 | len(_press("Left"))]) + b"\0\0\0\0" + _press("Left"))
    assert raw.recv(4096).startswith(b"HTTP/1.1 403")
    raw.close()
    assert meshcat.GetNumActiveConnections() == 0 and front.pages() == 0
    # The one authorised press counts once: none of the refused ones got through.
    with _websocket(front, f"?token={front.token}") as page:
        page.send(_press("Left"))
        assert _until(lambda: meshcat.GetButtonClicks("Left") == 1)
    time.sleep(0.1)
    assert meshcat.GetButtonClicks("Left") == 1


def _messages(page, until, timeout=5.0):
    """What `page` receives until `until(seen)` holds: Meshcat's messages as (type, path or
    name), our text frames as themselves (the panel's state decoded, FRAME as is)."""
    seen = []
    deadline = time.monotonic() + timeout
    while not until(seen) and time.monotonic() < deadline:
        try:
            raw = page.recv(timeout=max(0.01, deadline - time.monotonic()))
        except (TimeoutError, ConnectionClosed):
            break
        if isinstance(raw, str):
            seen.append(json.loads(raw) if raw.startswith("{") else raw)
        else:
            message = msgpack.unpackb(raw, raw=False)
            seen.append((message.get("type"), message.get("path", message.get("name"))))
    return seen


@pytest.mark.slow
def test_an_authorised_page_is_relayed_both_ways(meshcat, front):
    meshcat.AddButton("Left")
    with _websocket(front, f"?token={front.token}") as page:
        assert _until(lambda: meshcat.GetNumActiveConnections() == 1 and front.pages() == 1)
        page.send(_press("Left"))
        assert _until(lambda: meshcat.GetButtonClicks("Left") == 1)
        meshcat.SetObject("/box", Box(0.1, 0.2, 0.3), Rgba(1, 0, 0, 1))
        seen = _messages(page, lambda seen: ("set_object", "/box") in seen)
        assert ("set_control", "Left") in seen and ("set_object", "/box") in seen
        assert FRAME in seen  # each batch ends in one
    assert _until(lambda: meshcat.GetNumActiveConnections() == 0 and front.pages() == 0)


def _batch_of(path):
    """`until` for `_messages`: the batch holding `path`'s set_object, to its FRAME."""
    def until(seen):
        found = ("set_object", path)
        return found in seen and FRAME in seen[seen.index(found):]
    return until


@pytest.mark.slow
def test_a_paced_page_gets_the_next_batch_after_its_answer_and_the_panel_at_once(
        meshcat, front):
    with _websocket(front, f"?token={front.token}") as page:
        assert _until(lambda: front.pages() == 1)
        meshcat.SetObject("/a", Box(0.1, 0.1, 0.1), Rgba(1, 0, 0, 1))
        assert _batch_of("/a")(_messages(page, _batch_of("/a")))
        page.send(ACK)  # our page's answer: from now on the relay waits for each
        meshcat.SetObject("/b", Box(0.1, 0.1, 0.1), Rgba(1, 0, 0, 1))
        assert _batch_of("/b")(_messages(page, _batch_of("/b")))
        # Not answered: the scene waits, but the panel's state does not.
        meshcat.SetObject("/c", Box(0.1, 0.1, 0.1), Rgba(1, 0, 0, 1))
        front.show(status="time left 9 s", time=51.0)
        seen = _messages(page, lambda seen: False, timeout=1.0)
        assert ("set_object", "/c") not in seen
        assert any(isinstance(m, dict) and m["status"] == "time left 9 s" for m in seen)
        page.send(ACK)
        assert ("set_object", "/c") in _messages(
            page, lambda seen: ("set_object", "/c") in seen)


@pytest.mark.slow
def test_a_page_is_present_while_it_is_heard_and_its_tab_is_in_view(front, monkeypatch):
    monkeypatch.setattr("pbp_drake.console.front.SILENCE_LIMIT", 60.0)
    with _websocket(front, f"?token={front.token}") as page:
        # Connected, it is away until it says HERE (our page says it once it has drawn its
        # first batch): a page still loading its scene cannot be driven from.
        assert _until(lambda: front.pages() == 1) and front.pages_present() == 0
        assert front.pages_heard() == 0
        page.send(ACK)  # heard, but only HERE brings a page that is away
        assert _until(lambda: front.pages_heard() == 1) and front.pages_present() == 0
        page.send(HERE)
        assert _until(lambda: front.pages_present() == 1)
        page.send(AWAY)  # its tab hidden: nobody drives from it
        assert _until(lambda: front.pages_present() == 0)
        page.send(HERE)
        assert _until(lambda: front.pages_present() == 1)
        # Silent, its connection open (a sleeping laptop, a frozen tab): gone, until heard.
        monkeypatch.setattr("pbp_drake.console.front.SILENCE_LIMIT", 0.5)
        assert _until(lambda: front.pages_present() == 0) and front.pages() == 1
        monkeypatch.setattr("pbp_drake.console.front.SILENCE_LIMIT", 60.0)
        page.send(HERE)
        assert _until(lambda: front.pages_present() == 1)
    assert _until(lambda: front.pages() == 0) and front.pages_present() == 0


@pytest.mark.slow
def test_the_cookie_alone_opens_the_websocket(meshcat, front):
    cookie = {"Cookie": f"other=1; pbp_drake_token={front.token}"}
    with connect(f"ws://localhost:{front.port}/", origin=f"http://localhost:{front.port}",
                 additional_headers=cookie):
        assert _until(lambda: meshcat.GetNumActiveConnections() == 1)


@pytest.mark.slow
def test_the_panel_state_and_the_end(front):
    front.show(title="PBP-Alt", status="time left 41 s", time=3.25)
    front.show(result="success in 14.2 s", time=float("nan"))
    status, headers, body = _get(f"http://localhost:{front.port}/pbp/state?token={front.token}")
    assert status == 200 and headers["Cache-Control"] == "no-store"
    assert json.loads(body) == front.state()
    assert front.state() | {"seq": None} == {
        "title": "PBP-Alt", "status": "time left 41 s", "result": "success in 14.2 s",
        "notice": None, "time": None, "ended": False, "seq": None}
    front.show(time=4.5)
    assert json.loads(_get(front.url.replace("/?", "/pbp/state?"))[2])["time"] == 4.5
    started = time.monotonic()
    front.end("Session complete - you can close this page")  # no page relayed: no wait
    assert time.monotonic() - started < 1.0
    state = json.loads(_get(front.url.replace("/?", "/pbp/state?"))[2])
    assert state["ended"] is True and state["notice"].startswith("Session complete")
    with pytest.raises(TypeError, match="colour"):
        front.show(colour="red")


@pytest.mark.slow
def test_the_end_reaches_every_relayed_page_before_the_close(meshcat, front):
    with _websocket(front, f"?token={front.token}") as page:
        assert _until(lambda: front.pages() == 1)
        started = time.monotonic()
        front.end("Session complete - you can close this page", wait=5.0)
        assert time.monotonic() - started < 2.0  # sent: no need to wait out the 5 s
        front.close()
        ends = [m for m in _messages(page, lambda seen: False, timeout=2.0)
                if isinstance(m, dict) and m["ended"]]
        assert ends and ends[-1]["notice"] == "Session complete - you can close this page"


@pytest.mark.slow
def test_close_stops_serving_and_is_idempotent(meshcat):
    front = PageFront(meshcat.port())
    port = front.port
    front.close()
    front.close()
    with pytest.raises(OSError):
        socket.create_connection(("localhost", port), timeout=1.0).close()


@pytest.mark.slow
def test_a_taken_port_says_what_to_do():
    taken = bind_page_port(0)
    port = taken.getsockname()[1]
    with pytest.raises(PortError) as error:
        bind_page_port(port)
    assert str(error.value) == f"port {port} is in use (use --port 0 for a free one)"
    taken.close()


@pytest.mark.slow
def test_tokens():
    token = new_token()
    assert check_token(token) == token and len(token) == 32
    assert check_token("a" * 16) == "a" * 16 and check_token("A-_9" * 32)
    for bad in ["short", "a" * 129, "a" * 15 + "!", "a" * 20 + "\n", "é" * 20]:
        with pytest.raises(ValueError):
            check_token(bad)


def _transform(path, x):
    return msgpack.packb({"type": "set_transform", "path": path, "matrix": [x] * 16})


def _drain(queue):
    messages = []
    while queue:
        messages.append(msgpack.unpackb(queue.pop(), raw=False))
    return messages


@pytest.mark.slow
def test_message_keys():
    assert message_key(_transform("/a", 0)) == ("set_transform", "/a")
    assert message_key(msgpack.packb({"property": "visible", "type": "set_property",
                                      "path": "/a", "value": True})) == (
        "set_property", "/a", "visible")
    assert message_key(msgpack.packb({"type": "realtime_rate", "rate": 0.9})) == (
        "realtime_rate",)
    for barrier in [{"type": "set_object", "path": "/a", "object": {"data": b"\0" * 1000}},
                    {"type": "delete", "path": "/a"}]:
        assert message_key(msgpack.packb(barrier)) is None
    assert message_key(b"\xc1 not msgpack") is None and message_key("text") is None
    assert message_key(msgpack.packb([1, 2])) is None


@pytest.mark.slow
def test_the_queue_keeps_the_latest_of_a_key_and_the_order_across_barriers():
    queue = PendingMessages()
    for message in [_transform("/a", 1), _transform("/b", 1), _transform("/a", 2),
                    msgpack.packb({"type": "delete", "path": "/a"}), _transform("/a", 3),
                    _transform("/a", 4)]:
        queue.put(message_key(message), message)
    assert len(queue) == 4
    assert [(m["type"], m["path"], m.get("matrix", [None])[0]) for m in _drain(queue)] == [
        ("set_transform", "/a", 2), ("set_transform", "/b", 1), ("delete", "/a", None),
        ("set_transform", "/a", 4)]
    with pytest.raises(IndexError):
        queue.pop()


@pytest.mark.slow
def test_the_queue_stays_bounded_under_a_flood():
    queue = PendingMessages()
    paths = ["/robot/base", "/robot/arm", "/robot/hand"]
    for step in range(10_000):
        message = _transform(paths[step % 3], step)
        queue.put(message_key(message), message)
        assert len(queue) <= 3
    # Each path's latest pose, in the place its first pending pose took.
    assert [(m["path"], m["matrix"][0]) for m in _drain(queue)] == [
        ("/robot/base", 9999), ("/robot/arm", 9997), ("/robot/hand", 9998)]
    queue.put(None, b"barrier")
    queue.put(("set_transform", "/a"), b"after")
    assert [queue.pop(), queue.pop(), len(queue)] == [b"barrier", b"after", 0]
