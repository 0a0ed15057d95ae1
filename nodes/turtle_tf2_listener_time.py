"""The tf2 time tutorials' listeners: turtle_tf2_listener with its lookup changed.

"Using time" and "Traveling in time" edit one call of the listener
(``nodes/turtle_tf2_listener.py``); each version is one class here, run by
its own catalog name (``ros2 run learning_tf2_py turtle_tf2_listener_now``):

- ``now``: the transform at ``now()`` instead of time zero. It fails: the
  newest transforms in the buffer are a few milliseconds older than "now",
  so tf2 raises "Lookup would require extrapolation into the future", and
  turtle2 stays where it was spawned.
- ``wait``: the same with ``timeout=Duration(seconds=0.05)``: tf2 waits up to
  50 ms for the data to arrive, and turtle2 follows again.
- ``past``: ``lookup_transform`` at ``now - 5 s``: where the target was 5 s
  ago *relative to where turtle2 also was 5 s ago*, a question that makes
  turtle2 wander.
- ``full``: ``lookup_transform_full``: the target 5 s ago, carried through
  the fixed ``world`` frame into turtle2's frame *now*: turtle2 follows the
  target's trail 5 s behind.

Python note: a lookup with a timeout waits inside the timer callback, while
the TransformListener's subscriptions must keep filling the buffer. With
rclpy's single-threaded executor nothing else runs during the wait (so the
wait cannot succeed); the waiting versions spin on a MultiThreadedExecutor,
and the listener's subscriptions are in a reentrant callback group (rclpy's
executor, fixed for a bug of the Jazzy wheel that made it spin a whole core
here: nodes/common/executors.py).
"""

import sys

import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.utilities import remove_ros_args

from nodes.common.executors import SteadyMultiThreadedExecutor
from nodes.common.run import spin_node
from nodes.turtle_tf2_listener import FrameListener


class NowListener(FrameListener):
    """Using time, step 1: the transform at the current time, without waiting."""

    def lookup(self, to_frame_rel: str, from_frame_rel: str) -> TransformStamped:
        now = self.get_clock().now()
        return self.tf_buffer.lookup_transform(to_frame_rel, from_frame_rel, now)


class WaitingListener(FrameListener):
    """Using time, step 2: wait up to 50 ms for the transform at the current time."""

    def lookup(self, to_frame_rel: str, from_frame_rel: str) -> TransformStamped:
        now = self.get_clock().now()
        return self.tf_buffer.lookup_transform(
            to_frame_rel, from_frame_rel, now, timeout=rclpy.duration.Duration(seconds=0.05)
        )


class PastListener(FrameListener):
    """Traveling in time, first try: both frames 5 s ago."""

    def lookup(self, to_frame_rel: str, from_frame_rel: str) -> TransformStamped:
        when = self.get_clock().now() - rclpy.time.Duration(seconds=5.0)
        assert isinstance(when, rclpy.time.Time)  # Time - Duration is a Time (for mypy)
        return self.tf_buffer.lookup_transform(
            to_frame_rel, from_frame_rel, when, timeout=rclpy.duration.Duration(seconds=0.05)
        )


class TimeTravelListener(FrameListener):
    """Traveling in time: the target 5 s ago, seen from turtle2 now, through world."""

    def lookup(self, to_frame_rel: str, from_frame_rel: str) -> TransformStamped:
        when = self.get_clock().now() - rclpy.time.Duration(seconds=5.0)
        assert isinstance(when, rclpy.time.Time)  # Time - Duration is a Time (for mypy)
        return self.tf_buffer.lookup_transform_full(
            target_frame=to_frame_rel,
            target_time=rclpy.time.Time(),
            source_frame=from_frame_rel,
            source_time=when,
            fixed_frame="world",
            timeout=rclpy.duration.Duration(seconds=0.05),
        )


VERSIONS = {
    "now": NowListener,
    "wait": WaitingListener,
    "past": PastListener,
    "full": TimeTravelListener,
}


def main(args=None) -> None:
    words = remove_ros_args(sys.argv if args is None else args)
    version = words[1] if len(words) > 1 else ""
    if version not in VERSIONS:
        print(
            f"turtle_tf2_listener_time: say which version: {', '.join(VERSIONS)}", file=sys.stderr
        )
        raise SystemExit(2)
    executor = None if version == "now" else SteadyMultiThreadedExecutor
    spin_node(VERSIONS[version], args, executor=executor)


if __name__ == "__main__":
    main()
