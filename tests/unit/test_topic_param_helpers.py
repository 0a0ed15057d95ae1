"""Pure helpers of the Topics and Parameters panels: field lists, plot values, typed values."""

from __future__ import annotations

import math

import pytest
from geometry_msgs.msg import PointStamped, Twist
from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    ParameterType,
    ParameterValue,
)
from sensor_msgs.msg import JointState
from std_msgs.msg import String

from app.panels.parameters_panel import _nice_step, command_value, spec_from, value_for
from app.panels.topics_panel import NO_FIELD, numeric_fields, plot_value, preferred_field
from app.ros.rates import rate_text


def test_numeric_fields_include_nested_ones():
    assert numeric_fields(Twist) == [
        "linear.x", "linear.y", "linear.z", "angular.x", "angular.y", "angular.z",
    ]  # fmt: skip
    assert numeric_fields(PointStamped) == [
        "header.stamp.sec", "header.stamp.nanosec", "point.x", "point.y", "point.z",
    ]  # fmt: skip
    assert numeric_fields(String) == []
    assert "position" not in numeric_fields(JointState)  # arrays are not one number


def test_preferred_field_is_the_first_float():
    assert preferred_field(PointStamped) == "point.x"
    assert preferred_field(String) == NO_FIELD


def test_plot_value():
    msg = Twist()
    msg.linear.x = 1.5
    assert plot_value(msg, "linear.x") == 1.5
    assert plot_value(msg, "linear.nope") is None
    assert plot_value(String(data="7"), "data") is None
    msg.angular.z = math.nan
    assert plot_value(msg, "angular.z") is None


def test_spec_from_descriptor_ranges():
    value = ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=2.0)
    descriptor = ParameterDescriptor(
        type=ParameterType.PARAMETER_DOUBLE,
        description="messages per second",
        floating_point_range=[FloatingPointRange(from_value=0.1, to_value=20.0)],
    )
    spec = spec_from("publish_rate_hz", value, descriptor)
    assert (spec.value, spec.low, spec.high, spec.step) == (2.0, 0.1, 20.0, None)
    assert spec.type_word == "double"
    ints = ParameterDescriptor(integer_range=[IntegerRange(from_value=0, to_value=10, step=2)])
    spec = spec_from(
        "n", ParameterValue(type=ParameterType.PARAMETER_INTEGER, integer_value=4), ints
    )
    assert (spec.value, spec.low, spec.high, spec.step) == (4, 0.0, 10.0, 2.0)


def test_value_for_keeps_the_parameter_type():
    def spec(kind: int):
        return spec_from("p", ParameterValue(type=kind), ParameterDescriptor())

    assert value_for(spec(ParameterType.PARAMETER_DOUBLE), 5) == 5.0
    assert isinstance(value_for(spec(ParameterType.PARAMETER_DOUBLE), 5), float)
    assert value_for(spec(ParameterType.PARAMETER_INTEGER), 3.0) == 3
    with pytest.raises(ValueError):
        value_for(spec(ParameterType.PARAMETER_INTEGER), 3.5)
    assert value_for(spec(ParameterType.PARAMETER_STRING), "42") == "42"  # stays text
    assert value_for(spec(ParameterType.PARAMETER_BOOL), True) is True
    assert value_for(spec(ParameterType.PARAMETER_INTEGER_ARRAY), "[1, 2]") == [1, 2]


def test_command_value_as_typed_in_a_shell():
    assert command_value(True) == "true"
    assert command_value(5.0) == "5.0"
    assert command_value("Hello there") == "'Hello there'"
    assert command_value("") == "''"


def test_nice_step_reaches_round_values():
    assert _nice_step(19.9) == pytest.approx(0.1)
    assert _nice_step(1.0) == pytest.approx(0.01)
    assert _nice_step(1000) == pytest.approx(10)


def test_rate_text():
    assert rate_text(None) == ""
    assert rate_text(0.0) == "silent"
    assert rate_text(2.04) == "2.0 Hz"
    assert rate_text(1234.0) == "1234 Hz"
    # One message heard, a rate needs two: the edge of a talker that just started.
    assert rate_text(0.0, heard=True) == "measuring…"
    assert rate_text(2.04, heard=True) == "2.0 Hz"
    assert rate_text(None, heard=True) == ""
