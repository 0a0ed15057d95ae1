"""crashing_node: a node with a bug, to see what a crash looks like.

It logs a countdown and then raises an exception in its timer callback.
The exception leaves ``rclpy.spin``, Python prints the traceback and the
process ends with exit code 1, exactly as a real node with a bug would.
The dashboard shows it as *crashed (exit code 1)* with the traceback in the
log, and its Restart button starts it again.

Parameter ``crash_after_sec`` (float, default 3.0): how long it lives.
"""

from rclpy.node import Node

from nodes.common.run import spin_node


class CrashingNode(Node):
    def __init__(self) -> None:
        super().__init__("crashing_node")
        self.declare_parameter("crash_after_sec", 3.0)
        self.remaining = float(self.get_parameter("crash_after_sec").value)
        self.timer = self.create_timer(0.5, self.on_timer)

    def on_timer(self) -> None:
        if self.remaining <= 0.0:
            raise RuntimeError("simulated bug: this node crashes on purpose")
        self.get_logger().info(f"crashing in {self.remaining:.1f} s")
        self.remaining -= 0.5


def main(args=None) -> None:
    spin_node(CrashingNode, args)


if __name__ == "__main__":
    main()
