"""Meshcat's door: shut, it answers only the sockets `MeshcatDoor.connect` opened, from their
own address and port; a stranger's connection request gets no answer, whatever address or
port it comes from. Meshcat is used only from the test's thread."""

import gc
import socket

import pytest
from pydrake.geometry import Meshcat, MeshcatParams

from pbp_drake.console.meshcat_door import MeshcatDoor


@pytest.fixture(autouse=True)
def _meshcats_die_on_this_thread():
    yield
    gc.collect()  # see test_front.py: a Meshcat must die on the thread that made it


def _no_answer(family, address, port, source=None):
    stranger = socket.socket(family, socket.SOCK_STREAM)
    stranger.settimeout(1.0)
    try:
        if source is not None:
            stranger.bind(source)
        stranger.connect((address, port))
    except TimeoutError:
        return True
    finally:
        stranger.close()
    return False


@pytest.mark.slow
@pytest.mark.parametrize("host, family, address", [
    ("localhost", socket.AF_INET, "127.0.0.1"), ("::1", socket.AF_INET6, "::1")])
def test_a_shut_door_answers_its_own_sockets_alone(host, family, address):
    meshcat = Meshcat(MeshcatParams(host=host, port=0))
    door = MeshcatDoor(meshcat.port())
    assert door.shut and door.reason is None
    own = door.connect()
    assert own.getsockname()[0] == address
    assert _no_answer(family, address, meshcat.port())
    if family == socket.AF_INET:  # the admitted port, from another loopback address
        assert _no_answer(family, address, meshcat.port(), ("127.0.0.2", own.getsockname()[1]))
    body, kind = door.get("/")
    assert b"meshcat" in body.lower() and kind.startswith("text/html")
    with pytest.raises(OSError, match="404"):
        door.get("/no-such-file")
    door.release(own)
    door.close()
    assert _no_answer(family, address, meshcat.port())  # shut still, to everyone


@pytest.mark.slow
def test_a_meshcat_of_another_process_leaves_the_door_open_saying_why():
    with socket.create_server(("localhost", 0)) as elsewhere:
        # Not listening in this process under that port: a port nobody here listens on.
        port = elsewhere.getsockname()[1]
    door = MeshcatDoor(port)
    assert not door.shut
    assert door.reason == f"no socket of this process listens on port {port}"
