"""Exercise: a lifecycle node that sends a beacon only while active."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn
from std_msgs.msg import String


class Beacon(LifecycleNode):
    def __init__(self):
        super().__init__("beacon")
        # Nothing is created here: a lifecycle node acquires its resources
        # when it is configured, not when it is constructed.
        self.publisher = None
        self.timer = None
        self.count = 0

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        # TODO 1: create a *lifecycle* publisher of String on "beacon" (queue 10)
        #         and a 0.2 s timer that calls self.on_timer.
        self.get_logger().info("configured")
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("activated: the beacon is on")
        return super().on_activate(state)  # enables the lifecycle publisher

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("deactivated: the beacon is off")
        return super().on_deactivate(state)  # disables it again

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        # TODO 2: destroy the timer and the publisher (destroy_timer,
        #         destroy_lifecycle_publisher) and set both back to None.
        self.get_logger().info("cleaned up")
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        # TODO 3: release the same resources here (they may still exist).
        return TransitionCallbackReturn.SUCCESS

    def on_timer(self):
        if self.publisher is None:
            return
        self.publisher.publish(String(data=f"beacon {self.count}"))
        self.count += 1


def main():
    rclpy.init()
    node = Beacon()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
