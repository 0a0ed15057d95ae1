"""The listener's TFMessage reader against rclpy's own serializer and deserializer.

Random messages (empty, short and non-ASCII frame names, negative seconds,
any float) must read back field for field; truncated or foreign bytes must
give None (the listener then uses rclpy), never an exception.
"""

from __future__ import annotations

import random

from geometry_msgs.msg import TransformStamped
from rclpy.serialization import serialize_message
from tf2_msgs.msg import TFMessage
from tf2_ros._wire import decode_tf_message


def random_message(rng: random.Random) -> TFMessage:
    msg = TFMessage()
    for _ in range(rng.randint(0, 6)):
        t = TransformStamped()
        t.header.frame_id = "".join(rng.choice("abé_/x9") for _ in range(rng.randint(0, 9)))
        t.child_frame_id = "".join(rng.choice("abé_/y9") for _ in range(rng.randint(0, 9)))
        t.header.stamp.sec = rng.randint(-(2**31), 2**31 - 1)
        t.header.stamp.nanosec = rng.randint(0, 999_999_999)
        v = [rng.uniform(-1e6, 1e6) for _ in range(7)]
        tr, ro = t.transform.translation, t.transform.rotation
        tr.x, tr.y, tr.z, ro.x, ro.y, ro.z, ro.w = v
        msg.transforms.append(t)
    return msg


def test_reads_what_rclpy_writes_and_refuses_what_it_cannot_read():
    rng = random.Random(23)
    for _ in range(300):
        msg = random_message(rng)
        data = serialize_message(msg)
        got = decode_tf_message(data)
        assert got is not None and len(got) == len(msg.transforms)
        for entry, t in zip(got, msg.transforms, strict=True):
            tr, ro = t.transform.translation, t.transform.rotation
            stamp = t.header.stamp.sec * 1_000_000_000 + t.header.stamp.nanosec
            assert entry == (
                t.header.frame_id, t.child_frame_id, stamp,
                (tr.x, tr.y, tr.z), (ro.x, ro.y, ro.z, ro.w),
            )  # fmt: skip
        for cut in range(len(data) - 3):  # cut anywhere before the last padding: None
            assert decode_tf_message(data[:cut]) is None, (cut, len(data))
    assert decode_tf_message(b"") is None
    assert decode_tf_message(b"\x00\x07\x00\x00" + bytes(8)) is None  # XCDR2: rclpy's job
    assert decode_tf_message(b"\x00\x01\x00\x00\xff\xff\xff\x7f") is None  # absurd count
