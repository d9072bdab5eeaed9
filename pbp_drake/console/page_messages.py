"""What a run's page may send Meshcat: the messages Meshcat's own page sends, read strictly
(`read_page_message`; why: docs/design.md, "The page"). Any other frame is a `BadMessage`:

- `{"type": "button", "name": N}`: a button clicked, or its key pressed;
- `{"type": "slider", "name": N, "value": x}`: a slider moved (x finite);
- `{"type": "gamepad", "name": "", "gamepad": {}}` or with `{"index": i, "button_values":
  [0..1, ...], "axes": [-1..1, ...]}`: the first gamepad's state;
- `{"type": "camera_pose", "camera_pose": [16 finite numbers], "is_perspective": b}`.

Within `MAX_MESSAGE` bytes, `MAX_NAME` bytes a name, `MAX_ITEMS` gamepad buttons or axes; no
other key, no key twice, no trailing byte, no msgpack `bin`, `ext` or the byte `0xc1`.
"""

import math
import struct

import msgpack

MAX_MESSAGE = 4096
MAX_NAME = 256
MAX_ITEMS = 64
_MAX_DEPTH = 3  # the message, the gamepad's map, its lists


class BadMessage(ValueError):
    """A frame the page front does not pass to Meshcat; the text says why (no page data)."""


def read_page_message(frame):
    """The msgpack bytes to send Meshcat for `frame` (bytes from a page), a fresh encoding
    of one of the messages Meshcat's page sends; BadMessage, saying why, for anything else."""
    if not isinstance(frame, (bytes, bytearray, memoryview)):
        raise BadMessage("not a binary frame")
    frame = bytes(frame)
    if len(frame) > MAX_MESSAGE:
        raise BadMessage(f"over {MAX_MESSAGE} bytes")
    reader = _Reader(frame)
    message = reader.value(0)
    if reader.position != len(frame):
        raise BadMessage("bytes after the message")
    return msgpack.packb(_checked(message), use_bin_type=True)


def _checked(message):
    if not isinstance(message, dict):
        raise BadMessage("not a map")
    kind = message.get("type")
    if kind == "button":
        _keys(message, {"type", "name"})
        return {"type": kind, "name": _name(message["name"])}
    if kind == "slider":
        _keys(message, {"type", "name", "value"})
        return {"type": kind, "name": _name(message["name"]),
                "value": _number(message["value"], "the slider's value")}
    if kind == "gamepad":
        _keys(message, {"type", "name", "gamepad"})
        if message["name"] != "":
            raise BadMessage("a gamepad message's name is not empty")
        return {"type": kind, "name": "", "gamepad": _gamepad(message["gamepad"])}
    if kind == "camera_pose":
        _keys(message, {"type", "camera_pose", "is_perspective"})
        pose = message["camera_pose"]
        if not isinstance(pose, list) or len(pose) != 16:
            raise BadMessage("a camera pose is 16 numbers")
        if not isinstance(message["is_perspective"], bool):
            raise BadMessage("is_perspective is not true or false")
        return {"type": kind, "camera_pose": [_number(x, "a camera pose") for x in pose],
                "is_perspective": message["is_perspective"]}
    raise BadMessage("not a message type the page sends")


def _keys(message, expected):
    if set(message) != expected:
        raise BadMessage(f"a {message['type']} message has the keys {', '.join(sorted(expected))}")


def _name(name):
    if not isinstance(name, str) or not name:
        raise BadMessage("a control's name is not text")
    return name


def _number(value, what, low=-math.inf, high=math.inf):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise BadMessage(f"{what} is not a number")
    if not (math.isfinite(value) and low <= value <= high):
        raise BadMessage(f"{what} is out of range")
    return value


def _gamepad(gamepad):
    if not isinstance(gamepad, dict):
        raise BadMessage("a gamepad's state is not a map")
    if not gamepad:
        return {}  # no gamepad connected
    if set(gamepad) != {"index", "button_values", "axes"}:
        raise BadMessage("a gamepad's state has the keys axes, button_values, index")
    index = gamepad["index"]
    if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < MAX_ITEMS:
        raise BadMessage("a gamepad's index is out of range")
    lists = {}
    for key, low in (("button_values", 0.0), ("axes", -1.0)):
        values = gamepad[key]
        if not isinstance(values, list):
            raise BadMessage(f"a gamepad's {key} is not a list")
        lists[key] = [_number(x, f"a gamepad's {key}", low, 1.0) for x in values]
    return {"index": index, **lists}


class _Reader:
    """msgpack (https://github.com/msgpack/msgpack/blob/master/spec.md), the part a page
    uses: nil, booleans, integers, floats, str, arrays and maps with text keys."""

    def __init__(self, data):
        self.data, self.position = data, 0

    def take(self, size):
        end = self.position + size
        if end > len(self.data):
            raise BadMessage("a truncated message")
        chunk = self.data[self.position:end]
        self.position = end
        return chunk

    def unsigned(self, size):
        return int.from_bytes(self.take(size), "big")

    def value(self, depth):
        byte = self.unsigned(1)
        if byte <= 0x7f:
            return byte
        if byte >= 0xe0:
            return byte - 0x100
        if 0xa0 <= byte <= 0xbf:
            return self.text(byte & 0x1f)
        if 0x90 <= byte <= 0x9f:
            return self.array(byte & 0x0f, depth)
        if 0x80 <= byte <= 0x8f:
            return self.map(byte & 0x0f, depth)
        simple = {0xc0: None, 0xc2: False, 0xc3: True}
        if byte in simple:
            return simple[byte]
        if byte in (0xca, 0xcb):
            size = 4 if byte == 0xca else 8
            return struct.unpack(">f" if size == 4 else ">d", self.take(size))[0]
        if 0xcc <= byte <= 0xcf:
            return self.unsigned(1 << (byte - 0xcc))
        if 0xd0 <= byte <= 0xd3:
            return int.from_bytes(self.take(1 << (byte - 0xd0)), "big", signed=True)
        if byte in (0xd9, 0xda, 0xdb):
            return self.text(self.unsigned(1 << (byte - 0xd9)))
        if byte in (0xdc, 0xdd):
            return self.array(self.unsigned(2 if byte == 0xdc else 4), depth)
        if byte in (0xde, 0xdf):
            return self.map(self.unsigned(2 if byte == 0xde else 4), depth)
        raise BadMessage(f"the msgpack byte 0x{byte:02x} (bin, ext or never used)")

    def text(self, size):
        if size > MAX_NAME:
            raise BadMessage(f"a text over {MAX_NAME} bytes")
        try:
            return self.take(size).decode("utf-8")
        except UnicodeDecodeError:
            raise BadMessage("a text that is not UTF-8") from None

    def array(self, size, depth):
        self.nest(size, depth)
        return [self.value(depth + 1) for _ in range(size)]

    def map(self, size, depth):
        self.nest(size, depth)
        result = {}
        for _ in range(size):
            key = self.value(depth + 1)
            if not isinstance(key, str):
                raise BadMessage("a map key that is not text")
            if key in result:
                raise BadMessage("a map key given twice")
            result[key] = self.value(depth + 1)
        return result

    def nest(self, size, depth):
        if depth >= _MAX_DEPTH:
            raise BadMessage("nested too deep")
        if size > MAX_ITEMS:
            raise BadMessage(f"a list or map of over {MAX_ITEMS} items")
