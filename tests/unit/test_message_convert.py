"""Generic message <-> dict/YAML conversion, the console parser and the form filler."""

from __future__ import annotations

import numpy as np
import pytest
from geometry_msgs.msg import Twist
from hypothesis import given, settings
from hypothesis import strategies as st
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import Byte, String
from std_srvs.srv import SetBool
from tutorial_interfaces.action import Fibonacci

from app.ros.convert import (
    ConversionError,
    field_value,
    fill_from_form,
    from_yaml,
    import_type,
    leaf_fields,
    to_plain,
    to_yaml,
)
from app.ros2cli.interfaces import all_interfaces, show
from app.ros2cli.parser import UsageError, parse, split_command


def test_import_by_full_and_short_names():
    assert import_type("geometry_msgs/msg/Twist") is Twist
    assert import_type("std_srvs/SetBool") is SetBool
    assert import_type("tutorial_interfaces/action/Fibonacci") is Fibonacci
    assert import_type("std_msgs/String", "msg") is String


@pytest.mark.parametrize(
    ("name", "fragment"),
    [
        ("std_msgs/msg/Nope", "unknown message type 'std_msgs/msg/Nope'"),
        ("nope/Thing", "unknown message, service or action type"),
        ("std_msgs/thing/String", "must be msg, srv or action"),
        ("just_a_word", "malformed type name"),
        ("", "empty type name"),
    ],
)
def test_unknown_types_are_one_line(name, fragment):
    with pytest.raises(ConversionError) as info:
        import_type(name)
    assert fragment in str(info.value)
    assert "\n" not in str(info.value)


def test_nested_arrays_numpy_and_time_round_trip():
    info = from_yaml(
        CameraInfo,
        "{header: {stamp: {sec: 3, nanosec: 7}, frame_id: cam}, k: [1, 0, 2, 0, 1, 3, 0, 0, 1],"
        " d: [0.5, -0.25], binning_x: 2, roi: {do_rectify: true}}",
    )
    assert isinstance(info.k, np.ndarray) and info.k[2] == 2.0
    plain = to_plain(info)
    assert plain["header"] == {"stamp": {"sec": 3, "nanosec": 7}, "frame_id": "cam"}
    assert plain["k"] == [1.0, 0.0, 2.0, 0.0, 1.0, 3.0, 0.0, 0.0, 1.0]
    assert plain["roi"]["do_rectify"] is True
    again = from_yaml(CameraInfo, to_yaml(info, max_items=None))
    assert to_plain(again) == plain
    assert field_value(info, "header.frame_id") == "cam"
    assert field_value(info, "d[1]") == -0.25


def test_bytes_uint8_sequences_and_now():
    image = from_yaml(Image, "{header: {stamp: now}, data: [1, 2, 255], encoding: mono8}")
    assert to_plain(image)["data"] == [1, 2, 255]
    assert image.header.stamp.sec > 1_600_000_000
    assert to_plain(from_yaml(Byte, "{data: 7}")) == {"data": 7}
    assert to_yaml(String(data="Hello World: 1")) == "data: 'Hello World: 1'"
    assert to_yaml(Fibonacci.Result(sequence=[0, 1, 1])) == "sequence: [0, 1, 1]"


@pytest.mark.parametrize(
    ("cls", "text", "fragment"),
    [
        (Twist, "{linear: {x: fast}}", "field 'linear.x' (double) expects a number, got text"),
        (Twist, "{linear: {w: 1}}", "unknown field 'linear.w' in geometry_msgs/msg/Vector3"),
        (Twist, "{linear: 3}", "expects a mapping"),
        (Twist, "{linear: [", "malformed YAML"),
        (Twist, "[1, 2]", "must be a mapping"),
        (SetBool.Request, "{data: 1}", "expects true or false"),
        (Byte, "{data: 300}", "a byte (0-255)"),
        (CameraInfo, "{k: [1, 2]}", "needs exactly 9 items"),
        (CameraInfo, "{height: -1}", "must be between 0 and 4294967295"),
        (Image, "{data: 5}", "expects a list"),
    ],
)
def test_bad_values_are_one_clear_line(cls, text, fragment):
    with pytest.raises(ConversionError) as info:
        from_yaml(cls, text)
    assert fragment in str(info.value)
    assert "\n" not in str(info.value)


def test_form_fields_and_filler():
    kinds = {path: kind for path, _t, kind in leaf_fields(Twist)}
    assert kinds == {f"{v}.{a}": "float" for v in ("linear", "angular") for a in "xyz"}
    assert fill_from_form(Twist, {"linear.x": "1.5", "angular.z": -2.0}).linear.x == 1.5
    kinds = dict((p, k) for p, _t, k in leaf_fields(CameraInfo))
    assert kinds["header.frame_id"] == "text" and kinds["k"] == "yaml"
    assert kinds["roi.do_rectify"] == "bool" and kinds["height"] == "int"


def test_interfaces_from_the_ament_index():
    found = all_interfaces()
    assert "tutorial_interfaces/action/Fibonacci" in found["action"]
    assert "std_srvs/srv/SetBool" in found["srv"]
    assert "geometry_msgs/msg/Twist" in found["msg"]
    text = show("geometry_msgs/msg/Twist")
    assert "Vector3  linear" in text and "\tfloat64 x" in text


def test_console_parser_accepts_ros2_prefix_and_rejects_shell_syntax():
    assert split_command("ros2 topic list -t") == ["topic", "list", "-t"]
    assert split_command("topic pub /t std_msgs/String '{data: a b}'")[-1] == "{data: a b}"
    args = parse(split_command("ros2 topic echo /chatter --once"), print)
    assert (args.topic_name, args.once) == ("/chatter", True)
    with pytest.raises(UsageError):
        parse(split_command("ros2 topic list; rm -rf /"), print)
    with pytest.raises(UsageError):
        split_command("service call '/unclosed")


_text = st.text(alphabet=st.characters(codec="utf-8", exclude_categories=["Cs"]), max_size=80)
_words = st.lists(
    st.sampled_from(
        ["ros2", "topic", "echo", "list", "pub", "service", "call", "param", "set", "-t",
         "--once", "-r", "lifecycle", "/a", "std_msgs/msg/String", "'{data: 1}'", '"', "-h"]
    ),
    max_size=7,
).map(" ".join)  # fmt: skip


@settings(max_examples=300, deadline=None)
@given(st.one_of(_text, _words))
def test_random_console_text_never_escapes_as_a_traceback(text):
    lines: list[str] = []
    try:
        parse(split_command(text), lines.append)
    except UsageError as exc:
        assert str(exc).strip()
        # The text itself may say "Traceback" (the error quotes it); a traceback's header may not.
        assert "Traceback (most recent call last)" not in str(exc)


@settings(max_examples=300, deadline=None)
@given(
    st.dictionaries(
        st.sampled_from(["header.frame_id", "k", "height", "roi.do_rectify", "d", "binning_x"]),
        _text,
        max_size=6,
    )
)
def test_random_form_text_gives_a_message_or_one_line(values):
    try:
        msg = fill_from_form(CameraInfo, values)
    except ConversionError as exc:
        assert "\n" not in str(exc) and str(exc)
    else:
        assert isinstance(msg, CameraInfo)
