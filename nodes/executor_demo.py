"""executor_demo: how executors and callback groups decide what runs when.

The node has two timers:

- a *fast* timer that should tick 10 times a second and only counts;
- a *slow* timer that fires once a second and then blocks for 0.8 s,
  standing in for heavy work (a computation, a blocking call).

An executor is the loop that runs a node's callbacks. Which one runs it is
chosen by the parameter ``executor``:

- ``single`` (default): a ``SingleThreadedExecutor`` runs one callback at a
  time, so while the slow callback blocks, the fast one waits. Its measured
  rate collapses to about 3 Hz: the slow callback *starves* it.
- ``multi``: a ``MultiThreadedExecutor`` with two threads. The timers sit in
  two different ``MutuallyExclusiveCallbackGroup`` s, so one thread can run
  the fast timer while another is stuck in the slow one: about 10 Hz.
  (Threads alone are not enough: callbacks in one mutually exclusive group,
  such as a node's default group, never overlap whatever the executor.)

Every 2 s the node logs the measured rates and publishes the fast timer's
rate (``std_msgs/Float64``, Hz) on ``~/fast_rate``, i.e.
``/executor_demo/fast_rate``.

ROS concepts shown
- ``SingleThreadedExecutor`` vs ``MultiThreadedExecutor``,
  ``executor.add_node`` and ``executor.spin`` instead of ``rclpy.spin``
  (``main`` hands ``make_executor`` to ``spin_node``, nodes/common/run.py);
- callback groups passed as ``callback_group=`` to ``create_timer``;
- why a long callback hurts everything else on the same thread.

Try it: ``ros2 run tutorial_nodes executor_demo`` and
``ros2 run tutorial_nodes executor_demo --ros-args -r __node:=executor_demo_multi
-p executor:=multi``.
"""

import time
from collections import deque

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.executors import (
    Executor,
    MultiThreadedExecutor,
    SingleThreadedExecutor,
)
from rclpy.node import Node
from std_msgs.msg import Float64

from nodes.common.run import spin_node

FAST_PERIOD_SEC = 0.1  # expected 10 Hz
SLOW_PERIOD_SEC = 1.0
SLOW_WORK_SEC = 0.8  # the slow callback blocks this long
REPORT_PERIOD_SEC = 2.0
RATE_WINDOW_SEC = 4.0


def rate_hz(stamps: list[float]) -> float:
    """Mean rate of the events stamped (monotonic seconds, ascending)."""
    if len(stamps) < 2 or stamps[-1] <= stamps[0]:
        return 0.0
    return (len(stamps) - 1) / (stamps[-1] - stamps[0])


class ExecutorDemo(Node):
    def __init__(self) -> None:
        super().__init__("executor_demo")
        self.executor_kind = self.declare_parameter(
            "executor",
            "single",
            ParameterDescriptor(read_only=True, description="single or multi (at start-up)"),
        ).value
        if self.executor_kind not in ("single", "multi"):
            raise ValueError(f"executor must be 'single' or 'multi', got {self.executor_kind!r}")
        self.fast_group = MutuallyExclusiveCallbackGroup()
        self.slow_group = MutuallyExclusiveCallbackGroup()
        self.fast_ticks: deque[float] = deque()
        self.slow_ticks: deque[float] = deque()
        self.rate_publisher = self.create_publisher(Float64, "~/fast_rate", 10)
        self.fast_timer = self.create_timer(
            FAST_PERIOD_SEC, self.on_fast_timer, callback_group=self.fast_group
        )
        self.slow_timer = self.create_timer(
            SLOW_PERIOD_SEC, self.on_slow_timer, callback_group=self.slow_group
        )
        # The report shares the fast group: it is starved just like the fast timer.
        self.report_timer = self.create_timer(
            REPORT_PERIOD_SEC, self.on_report_timer, callback_group=self.fast_group
        )
        self.get_logger().info(f"Running with the {self.executor_kind}-threaded executor")

    def make_executor(self) -> Executor:
        if self.executor_kind == "multi":
            return MultiThreadedExecutor(num_threads=2)
        return SingleThreadedExecutor()

    def on_fast_timer(self) -> None:
        self.fast_ticks.append(time.monotonic())

    def on_slow_timer(self) -> None:
        self.slow_ticks.append(time.monotonic())
        time.sleep(SLOW_WORK_SEC)  # heavy work that blocks its thread

    def on_report_timer(self) -> None:
        now = time.monotonic()
        for ticks in (self.fast_ticks, self.slow_ticks):
            while ticks and now - ticks[0] > RATE_WINDOW_SEC:
                ticks.popleft()
        fast = rate_hz(list(self.fast_ticks))
        slow = rate_hz(list(self.slow_ticks))
        self.rate_publisher.publish(Float64(data=fast))
        self.get_logger().info(
            f"[{self.executor_kind}] fast timer {fast:.1f} Hz "
            f"(expected {1 / FAST_PERIOD_SEC:.0f}), slow timer {slow:.1f} Hz"
        )


def main(args=None) -> None:
    # make_executor picks the executor from the parameter; spin_node then calls
    # executor.add_node(node) and executor.spin() instead of rclpy.spin(node).
    spin_node(ExecutorDemo, args, executor=ExecutorDemo.make_executor, program="executor_demo")


if __name__ == "__main__":
    main()
