"""tf2_msgs/TFMessage read straight from its CDR bytes, for the listener's hot path.

rclpy turns each received message into Python message objects, about 20 us
per TransformStamped here: most of what a listener costs. The C++ listener
reads the same bytes with no such cost. A TFMessage's layout is fixed (a
sequence of: stamp, frame_id, child_frame_id, 3 + 4 float64), so it is read
here with ``struct`` into plain tuples. Anything else (another encapsulation,
a short or malformed buffer) gives None, and the caller uses rclpy's
deserializer instead, which reports the problem its own way.
"""

from __future__ import annotations

import struct

Entry = tuple[str, str, int, tuple[float, float, float], tuple[float, float, float, float]]

_LE = (struct.Struct("<I"), struct.Struct("<iI"), struct.Struct("<7d"))
_BE = (struct.Struct(">I"), struct.Struct(">iI"), struct.Struct(">7d"))
_ORIGIN = 4  # CDR aligns relative to the first byte after the encapsulation header


def decode_tf_message(data: bytes) -> list[Entry] | None:
    """(frame_id, child_frame_id, stamp in ns, translation, rotation xyzw) per transform."""
    if len(data) < 8 or data[0] != 0:
        return None
    if data[1] == 1:
        u32, stamp, doubles = _LE
    elif data[1] == 0:
        u32, stamp, doubles = _BE
    else:
        return None  # XCDR2 or anything newer: rclpy reads it
    try:
        (count,) = u32.unpack_from(data, 4)
        if count * 72 > len(data):  # each transform takes at least 72 bytes
            return None
        pos = 8
        out: list[Entry] = []
        for _ in range(count):
            pos += -(pos - _ORIGIN) % 4
            sec, nanosec = stamp.unpack_from(data, pos)
            pos += 8
            names = []
            for _field in (0, 1):
                pos += -(pos - _ORIGIN) % 4
                (size,) = u32.unpack_from(data, pos)
                pos += 4
                end = pos + size
                if size == 0:
                    names.append("")
                    continue
                if end > len(data) or data[end - 1] != 0:
                    return None
                names.append(data[pos : end - 1].decode("utf-8"))
                pos = end
            pos += -(pos - _ORIGIN) % 8
            v = doubles.unpack_from(data, pos)
            pos += 56
            out.append((names[0], names[1], sec * 1_000_000_000 + nanosec, v[:3], v[3:]))
        return out
    except (struct.error, UnicodeDecodeError):
        return None
