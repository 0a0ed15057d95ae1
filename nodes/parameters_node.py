"""parameters_node: a node whose behaviour is set by parameters, even while it runs.

It publishes a greeting on ``/greeting`` (``std_msgs/String``) and logs it.
Three parameters drive it:

- ``greeting`` (string): the text, e.g. "Hello" gives "Hello from parameters_node #7";
- ``publish_rate_hz`` (double, 0.1 to 20.0): how often it publishes;
- ``shout`` (bool): send the text in capitals.

Each is *declared* with a ``ParameterDescriptor`` that gives its type, a
description and, for the rate, an allowed range. ROS itself refuses a value
of the wrong type or outside the range. Rules a descriptor cannot express
(here: the greeting must not be empty nor longer than 60 characters) are
checked in a set-parameters callback, which refuses with a reason the caller
sees. Only once a change is accepted does a post-set callback apply it: a new
rate rebuilds the timer at once.

ROS concepts shown
- ``declare_parameter(name, default, descriptor)``; ``FloatingPointRange``;
- ``add_on_set_parameters_callback``: validate, return
  ``SetParametersResult(successful=False, reason=...)`` to refuse;
- ``add_post_set_parameters_callback``: react to accepted changes;
- overriding a default at start-up: ``--ros-args -p publish_rate_hz:=5.0``.

Try it: ``ros2 run tutorial_nodes parameters_node``, then from a full ROS install
``ros2 param set /parameters_node publish_rate_hz 10.0`` (accepted) or
``ros2 param set /parameters_node publish_rate_hz 100.0`` (refused).
"""

from rcl_interfaces.msg import (
    FloatingPointRange,
    ParameterDescriptor,
    ParameterType,
    SetParametersResult,
)
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_msgs.msg import String

from nodes.common.run import spin_node

MAX_GREETING_CHARS = 60


class ParametersNode(Node):
    def __init__(self) -> None:
        super().__init__("parameters_node")
        self.declare_parameter(
            "greeting",
            "Hello",
            ParameterDescriptor(
                type=ParameterType.PARAMETER_STRING,
                description=f"text to publish (1 to {MAX_GREETING_CHARS} characters)",
            ),
        )
        self.declare_parameter(
            "publish_rate_hz",
            2.0,
            ParameterDescriptor(
                type=ParameterType.PARAMETER_DOUBLE,
                description="messages per second",
                floating_point_range=[FloatingPointRange(from_value=0.1, to_value=20.0)],
            ),
        )
        self.declare_parameter(
            "shout",
            False,
            ParameterDescriptor(
                type=ParameterType.PARAMETER_BOOL, description="publish in capital letters"
            ),
        )
        self.add_on_set_parameters_callback(self.on_set_parameters)
        self.add_post_set_parameters_callback(self.on_parameters_set)
        self.count = 0
        self.publisher = self.create_publisher(String, "greeting", 10)
        self.timer = self.create_timer(self.period_sec(), self.on_timer)

    def period_sec(self) -> float:
        return 1.0 / self.get_parameter("publish_rate_hz").value

    def on_set_parameters(self, params: list[Parameter]) -> SetParametersResult:
        """Validate a change before it happens; type and range were checked already."""
        for param in params:
            if param.name == "greeting":
                text = param.value.strip()
                if not text:
                    return SetParametersResult(
                        successful=False, reason="greeting must not be empty"
                    )
                if len(text) > MAX_GREETING_CHARS:
                    return SetParametersResult(
                        successful=False,
                        reason=f"greeting must be at most {MAX_GREETING_CHARS} characters, "
                        f"got {len(text)}",
                    )
        return SetParametersResult(successful=True)

    def on_parameters_set(self, params: list[Parameter]) -> None:
        """Apply accepted changes."""
        for param in params:
            self.get_logger().info(f"Parameter {param.name} is now {param.value!r}")
            if param.name == "publish_rate_hz":
                self.destroy_timer(self.timer)
                self.timer = self.create_timer(self.period_sec(), self.on_timer)

    def on_timer(self) -> None:
        text = f"{self.get_parameter('greeting').value} from parameters_node #{self.count}"
        if self.get_parameter("shout").value:
            text = text.upper()
        self.publisher.publish(String(data=text))
        self.get_logger().info(f'Publishing: "{text}"')
        self.count += 1


def main(args=None) -> None:
    spin_node(ParametersNode, args)


if __name__ == "__main__":
    main()
