"""lifecycle_talker: a managed (lifecycle) node that only talks while active.

A lifecycle node starts *unconfigured* and is moved between states by
transitions that someone else requests (a launch file, an operator, the
dashboard's lifecycle panel, or ``ros2 lifecycle set``):

    unconfigured --configure--> inactive --activate--> active
    active --deactivate--> inactive --cleanup--> unconfigured
    any of the three --shutdown--> finalized

Each transition runs one of our callbacks, and each callback here really
acquires or releases something:

- ``on_configure`` creates the lifecycle publisher (``/lifecycle_chatter``,
  ``std_msgs/String``) and the timer that feeds it;
- ``on_activate`` enables the publisher (the base class does that), and
  messages start to flow;
- ``on_deactivate`` disables it again: the timer keeps ticking, but a
  lifecycle publisher drops what it is given while inactive, so nothing is
  sent;
- ``on_cleanup`` destroys the timer and publisher, back to a blank node;
- ``on_shutdown`` releases whatever still exists before the node is finalized.

A callback returns SUCCESS to complete its transition or FAILURE to refuse
it; on FAILURE the node stays in the state it was in. To see that path, set
the parameter ``fail_on`` to a transition name (``configure``, ``activate``,
``deactivate``, ``cleanup`` or ``shutdown``): that transition then fails on
purpose, with an error in the log, until ``fail_on`` is set back to "".

ROS concepts shown
- ``rclpy.lifecycle.LifecycleNode`` and its services
  ``/lifecycle_talker/change_state`` and ``/lifecycle_talker/get_state``
  (through ``GuardedLifecycleNode``, nodes/common/lifecycle_guard.py: a
  transition that is impossible from the current state is refused with
  ``success: false`` and a warning, as rclcpp does, instead of ending the node);
- ``create_lifecycle_publisher``; ``TransitionCallbackReturn``;
- a parameter whose allowed values are checked by a set-parameters callback.

Try it: ``ros2 run tutorial_nodes lifecycle_talker``, then from a full ROS install
``ros2 lifecycle set /lifecycle_talker configure`` and ``... activate``.
"""

from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor, SetParametersResult
from rclpy.lifecycle import LifecycleState, TransitionCallbackReturn
from rclpy.lifecycle.publisher import LifecyclePublisher
from rclpy.parameter import Parameter
from rclpy.timer import Timer
from std_msgs.msg import String

from nodes.common.lifecycle_guard import GuardedLifecycleNode
from nodes.common.run import spin_node

TRANSITIONS = ("configure", "activate", "deactivate", "cleanup", "shutdown")


class LifecycleTalker(GuardedLifecycleNode):
    def __init__(self) -> None:
        super().__init__("lifecycle_talker")
        self.declare_parameter(
            "fail_on",
            "",
            ParameterDescriptor(
                description="name of a transition to fail on purpose, or empty: "
                + ", ".join(TRANSITIONS)
            ),
        )
        self.declare_parameter(
            "publish_period",
            1.0,
            ParameterDescriptor(
                description="seconds between two messages (read at configure)",
                floating_point_range=[FloatingPointRange(from_value=0.05, to_value=10.0)],
            ),
        )
        self.add_on_set_parameters_callback(self.on_set_parameters)
        self.publisher: LifecyclePublisher | None = None
        self.timer: Timer | None = None
        self.count = 0
        self.get_logger().info("Created in state 'unconfigured': configure me to start")

    def on_set_parameters(self, params: list[Parameter]) -> SetParametersResult:
        for param in params:
            if param.name == "fail_on" and param.value not in ("", *TRANSITIONS):
                return SetParametersResult(
                    successful=False,
                    reason=f"fail_on must be empty or one of {', '.join(TRANSITIONS)}; "
                    f"got {param.value!r}",
                )
        return SetParametersResult(successful=True)

    def should_fail(self, transition: str) -> bool:
        if self.get_parameter("fail_on").value != transition:
            return False
        self.get_logger().error(
            f"on_{transition}: failing on purpose (parameter fail_on={transition!r}); "
            "the node stays in its current state"
        )
        return True

    # -- transition callbacks ---------------------------------------------

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        if self.should_fail("configure"):
            return TransitionCallbackReturn.FAILURE
        period = self.get_parameter("publish_period").value
        self.publisher = self.create_lifecycle_publisher(String, "lifecycle_chatter", 10)
        self.timer = self.create_timer(period, self.on_timer)
        self.get_logger().info(
            f"on_configure: created the publisher on /lifecycle_chatter and a {period} s timer"
        )
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        if self.should_fail("activate"):
            return TransitionCallbackReturn.FAILURE
        self.get_logger().info("on_activate: publisher enabled, messages will be sent")
        return super().on_activate(state)  # enables every lifecycle publisher

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        if self.should_fail("deactivate"):
            return TransitionCallbackReturn.FAILURE
        self.get_logger().info("on_deactivate: publisher disabled, messages are dropped")
        return super().on_deactivate(state)

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        if self.should_fail("cleanup"):
            return TransitionCallbackReturn.FAILURE
        self.release_resources()
        self.get_logger().info("on_cleanup: destroyed the timer and the publisher")
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        if self.should_fail("shutdown"):
            return TransitionCallbackReturn.FAILURE
        self.release_resources()
        self.get_logger().info(f"on_shutdown from '{state.label}': everything released")
        return TransitionCallbackReturn.SUCCESS

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.release_resources()
        self.get_logger().error(f"on_error in '{state.label}': released everything")
        return TransitionCallbackReturn.SUCCESS  # back to unconfigured

    # -- work ----------------------------------------------------------------

    def on_timer(self) -> None:
        if self.publisher is None:
            return
        msg = String(data=f"Lifecycle Hello World: {self.count}")
        self.count += 1
        # A lifecycle publisher silently drops the message unless the node is active.
        self.publisher.publish(msg)
        if self.publisher.is_activated:
            self.get_logger().info(f'Publishing: "{msg.data}"')

    def release_resources(self) -> None:
        if self.timer is not None:
            self.destroy_timer(self.timer)
            self.timer = None
        if self.publisher is not None:
            self.destroy_lifecycle_publisher(self.publisher)
            self.publisher = None


def main(args=None) -> None:
    spin_node(LifecycleTalker, args)


if __name__ == "__main__":
    main()
