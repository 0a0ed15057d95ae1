"""Mistake: cleanup reports success but keeps the publisher and timer."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn
from std_msgs.msg import String


class Beacon(LifecycleNode):
    def __init__(self):
        super().__init__("beacon")
        self.publisher = None
        self.timer = None
        self.count = 0

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.publisher = self.create_lifecycle_publisher(String, "beacon", 10)
        self.timer = self.create_timer(0.2, self.on_timer)
        self.get_logger().info("configured: publisher and timer created")
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("activated: the beacon is on")
        return super().on_activate(state)  # enables the lifecycle publisher

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("deactivated: the beacon is off")
        return super().on_deactivate(state)  # disables it again

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("cleaned up: publisher and timer destroyed")
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.release()
        return TransitionCallbackReturn.SUCCESS

    def release(self):
        if self.timer is not None:
            self.destroy_timer(self.timer)
            self.timer = None
        if self.publisher is not None:
            self.destroy_lifecycle_publisher(self.publisher)
            self.publisher = None

    def on_timer(self):
        # While the node is inactive, a lifecycle publisher drops the message.
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
