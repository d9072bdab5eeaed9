"""The page's messages, read strictly: what Meshcat's page sends passes, freshly encoded;
every byte string Meshcat's own parser dies on, and every other message, is refused with a
reason. The frames are written out by hand from the msgpack spec."""

import math
import struct

import msgpack
import pytest

from pbp_drake.console.page_messages import (
    MAX_ITEMS, MAX_MESSAGE, MAX_NAME, BadMessage, read_page_message)

# {"type": "button", "name": "Left"}, byte by byte: a fixmap of 2, fixstr keys and values.
BUTTON = b"\x82\xa4type\xa6button\xa4name\xa4Left"
PAGE_SENDS = [
    {"type": "button", "name": "Left (←)"},
    {"type": "slider", "name": "Real-time rate", "value": 0.5},
    {"type": "slider", "name": "alpha", "value": 1},
    {"type": "gamepad", "name": "", "gamepad": {}},
    {"type": "gamepad", "name": "", "gamepad": {
        "index": 0, "button_values": [0, 0.25, 1] + [0] * 14, "axes": [-1, 0.03, 0, 1]}},
    {"type": "camera_pose", "camera_pose": [1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0, 0,
                                            0.5, -2.0, 1.25, 1.0], "is_perspective": True},
]


def test_a_button_frame_written_from_the_spec():
    assert read_page_message(BUTTON) == msgpack.packb({"type": "button", "name": "Left"})


@pytest.mark.parametrize("message", PAGE_SENDS, ids=lambda m: m["type"])
def test_what_the_page_sends_passes(message):
    frame = msgpack.packb(message)
    assert msgpack.unpackb(read_page_message(frame)) == message
    # The key order is the sender's.
    reordered = msgpack.packb(dict(reversed(list(message.items()))))
    assert msgpack.unpackb(read_page_message(reordered)) == message


HOSTILE = {
    "the never-used byte 0xc1": b"\xc1",
    "a truncated map": BUTTON[:-3],
    "a map announcing 2**32-1 pairs": b"\xdf\xff\xff\xff\xff" + BUTTON[1:],
    "an array announcing 2**32-1 items": b"\xdd\xff\xff\xff\xff",
    "a str announcing 2**32-1 bytes": b"\x81\xa4type\xdb\xff\xff\xff\xff",
    "a bin": b"\x81\xa4type\xc4\x06button",
    "an ext": b"\x81\xa4type\xd4\x01\x00",
    "a trailing byte": BUTTON + b"\x00",
    "an empty frame": b"",
    "not a map": b"\x93\x01\x02\x03",
    "a key given twice": b"\x83\xa4type\xa6button\xa4name\xa4Left\xa4name\xa4Down",
    "a key that is not text": b"\x82\x01\xa6button\xa4name\xa4Left",
    "text that is not UTF-8": b"\x82\xa4type\xa6button\xa4name\xa2\xff\xfe",
    "nesting": b"\x81\xa4type" + b"\x91" * 10 + b"\x01",
}


@pytest.mark.parametrize("frame", HOSTILE.values(), ids=HOSTILE.keys())
def test_frames_that_are_not_msgpack_or_too_big_are_refused(frame):
    with pytest.raises(BadMessage):
        read_page_message(frame)


WRONG = {
    "an unknown type": ({"type": "set_transform", "path": "/a"}, "not a message type"),
    "no type": ({"name": "Left"}, "not a message type"),
    "a text frame": ("pbp_drake_frame", "not a binary frame"),
    "an extra key": ({"type": "button", "name": "Left", "x": 1}, "has the keys name, type"),
    "a number as the name": ({"type": "button", "name": 7}, "name is not text"),
    "an empty name": ({"type": "button", "name": ""}, "name is not text"),
    "a NaN slider": ({"type": "slider", "name": "alpha", "value": math.nan}, "out of range"),
    "an infinite slider": ({"type": "slider", "name": "a", "value": math.inf}, "out of range"),
    "a true slider": ({"type": "slider", "name": "alpha", "value": True}, "not a number"),
    "a named gamepad": ({"type": "gamepad", "name": "x", "gamepad": {}}, "name is not empty"),
    "a gamepad axis past 1": ({"type": "gamepad", "name": "", "gamepad": {
        "index": 0, "button_values": [], "axes": [1.5]}}, "out of range"),
    "a negative button": ({"type": "gamepad", "name": "", "gamepad": {
        "index": 0, "button_values": [-0.5], "axes": []}}, "out of range"),
    "a gamepad index of 64": ({"type": "gamepad", "name": "", "gamepad": {
        "index": MAX_ITEMS, "button_values": [], "axes": []}}, "index is out of range"),
    "a gamepad state of a list": ({"type": "gamepad", "name": "", "gamepad": [0]},
                                  "state is not a map"),
    "a gamepad without axes": ({"type": "gamepad", "name": "", "gamepad": {
        "index": 0, "button_values": []}}, "has the keys axes, button_values, index"),
    "a gamepad's axes as a map": ({"type": "gamepad", "name": "", "gamepad": {
        "index": 0, "button_values": [], "axes": {}}}, "axes is not a list"),
    "15 numbers of a pose": ({"type": "camera_pose", "camera_pose": [0.0] * 15,
                              "is_perspective": False}, "16 numbers"),
    "a pose's flag of 1": ({"type": "camera_pose", "camera_pose": [0.0] * 16,
                            "is_perspective": 1}, "not true or false"),
}


@pytest.mark.parametrize("message, reason", WRONG.values(), ids=WRONG.keys())
def test_messages_the_page_does_not_send_are_refused_saying_why(message, reason):
    frame = message if isinstance(message, str) else msgpack.packb(message)
    with pytest.raises(BadMessage, match=reason):
        read_page_message(frame)


def test_the_limits():
    longest = "x" * MAX_NAME
    assert read_page_message(msgpack.packb({"type": "button", "name": longest}))
    with pytest.raises(BadMessage, match=f"over {MAX_NAME} bytes"):
        read_page_message(msgpack.packb({"type": "button", "name": longest + "x"}))
    many = {"type": "gamepad", "name": "", "gamepad": {
        "index": 0, "button_values": [0] * MAX_ITEMS, "axes": [0] * MAX_ITEMS}}
    assert read_page_message(msgpack.packb(many))
    many["gamepad"]["axes"].append(0)
    with pytest.raises(BadMessage, match=f"over {MAX_ITEMS} items"):
        read_page_message(msgpack.packb(many))
    with pytest.raises(BadMessage, match=f"over {MAX_MESSAGE} bytes"):
        read_page_message(BUTTON + b"\0" * MAX_MESSAGE)
    # Every width of integer and float the spec has reads as its value.
    for packed, value in [(b"\xcc\xff", 255), (b"\xcd\x01\x00", 256), (b"\xd0\xff", -1),
                          (b"\xd1\x80\x00", -32768), (b"\xe0", -32),
                          (b"\xcb" + struct.pack(">d", 0.1), 0.1),
                          (b"\xca" + struct.pack(">f", 0.5), 0.5)]:
        frame = b"\x83\xa4type\xa6slider\xa4name\xa1a\xa5value" + packed
        assert msgpack.unpackb(read_page_message(frame))["value"] == value
