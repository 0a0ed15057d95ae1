"""tf2_monitor [FRAMEA FRAMEB]: delays of /tf data, per frame and overall, as upstream prints them.

Every 10 s (21 rounds of 0.5 s) it prints the results: with two frames, the
chain between them and the net delay of the latest lookup; for every frame
the average and maximum delay between a transform's stamp and its arrival;
and per broadcaster the rate and delays (upstream knows no authority over
DDS, so it prints ``<no authority available>``, as here).
"""

from __future__ import annotations

import sys
import threading
import time

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile
from rclpy.time import Time
from tf2_msgs.msg import TFMessage

from tf2_ros import TransformException
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener

AUTHORITY = "<no authority available>"
KEEP = 1000


def g(value: float) -> str:
    """A double as C++'s default stream prints it (6 significant digits)."""
    return f"{value:g}"


class TFMonitor:
    def __init__(self, node: Node, framea: str = "", frameb: str = "") -> None:
        self.node = node
        self.framea, self.frameb = framea, frameb
        self.specific = bool(framea)
        self.lock = threading.Lock()
        self.delays: dict[str, list[float]] = {}
        self.authority_delays: dict[str, list[float]] = {}
        self.authority_times: dict[str, list[float]] = {}
        self.chain: list[str] = []
        self.buffer = Buffer(node=node)
        self.listener = TransformListener(self.buffer, node)
        dynamic = QoSProfile(depth=100, history=HistoryPolicy.KEEP_LAST)
        static = QoSProfile(
            depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL, history=HistoryPolicy.KEEP_LAST
        )
        node.create_subscription(TFMessage, "/tf", self.callback, dynamic)
        node.create_subscription(TFMessage, "/tf_static", self.callback, static)

    def now(self) -> float:
        return self.node.get_clock().now().nanoseconds / 1e9

    def callback(self, message: TFMessage) -> None:
        with self.lock:
            offsets = []
            for t in message.transforms:
                offset = self.now() - (t.header.stamp.sec + t.header.stamp.nanosec / 1e9)
                offsets.append(offset)
                kept = self.delays.setdefault(t.child_frame_id, [])
                kept.append(offset)
                del kept[:-KEEP]
            average = sum(offsets) / max(1, len(offsets))
            self.authority_delays.setdefault(AUTHORITY, []).append(average)
            del self.authority_delays[AUTHORITY][:-KEEP]
            self.authority_times.setdefault(AUTHORITY, []).append(self.now())
            del self.authority_times[AUTHORITY][:-KEEP]

    def wait_for_chain(self) -> None:
        while rclpy.ok():
            ready, why = self.buffer.can_transform_core(self.framea, self.frameb, Time())
            if ready:
                break
            self.node.get_logger().info(
                f"Waiting for transform {self.framea} ->  {self.frameb}: {why}",
                throttle_duration_sec=1.0,
            )
            time.sleep(0.5)
        self.chain = self.buffer._chain(self.frameb, Time(), self.framea, Time(), self.frameb)

    def frame_line(self, frame: str, delays: list[float]) -> str:
        return (
            f"Frame: {frame}, published by {AUTHORITY}, Average Delay: "
            f"{g(sum(delays) / len(delays))}, Max Delay: {g(max(0.0, *delays))}"
        )

    def spin(self) -> None:
        max_diff = avg_diff = 0.0
        counter = 0
        if self.specific:
            print(f"Gathering data on {self.framea} -> {self.frameb} for 10 seconds...", flush=True)
        else:
            print("Gathering data on all frames for 10 seconds...", flush=True)
        while rclpy.ok():
            counter += 1
            if self.specific:
                try:
                    t = self.buffer.lookup_transform(self.framea, self.frameb, Time())
                    diff = self.now() - (t.header.stamp.sec + t.header.stamp.nanosec / 1e9)
                    avg_diff = 0.01 * diff + 0.99 * avg_diff
                    max_diff = max(max_diff, diff)
                except TransformException as ex:
                    self.node.get_logger().warning(f"Transform Exception {ex}")
            time.sleep(0.5)
            if counter <= 20:
                continue
            counter = 0
            out = ["", "", ""]
            if self.specific:
                out.append(f"RESULTS: for {self.framea} to {self.frameb}")
                out.append("Chain is: " + " -> ".join(self.chain))
                out.append(f"Net delay     avg = {g(avg_diff)}: max = {g(max_diff)}")
            else:
                out.append("RESULTS: for all Frames")
            with self.lock:
                out += ["", "Frames:"]
                for frame in sorted(self.delays):
                    if not self.specific or frame in self.chain:
                        out.append(self.frame_line(frame, self.delays[frame]))
                out += ["", "All Broadcasters:"]
                for name in sorted(self.authority_delays):
                    delays, times = self.authority_delays[name], self.authority_times[name]
                    rate = len(times) / max(0.00000001, times[-1] - times[0])
                    out.append(
                        f"Node: {name} {g(rate)} Hz, Average Delay: "
                        f"{g(sum(delays) / len(delays))} Max Delay: {g(max(0.0, *delays))}"
                    )
            print("\n".join(out), flush=True)


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    args = rclpy.utilities.remove_ros_args(argv)
    rclpy.init(args=argv)
    node = Node("tf2_monitor_main")
    executor = SingleThreadedExecutor()
    stop = threading.Event()
    spinner: threading.Thread | None = None

    def spin() -> None:
        # Executor.spin() ends only through Executor.shutdown(), which destroys the guard
        # conditions the spinning thread still waits on; that thread then frees them while
        # the signal's context shutdown runs, and crashed once (SIGSEGV on SIGTERM, CI of
        # 2026-12-04). A flag of our own ends the loop with nothing destroyed under it.
        while not stop.is_set() and executor.context.ok():
            executor.spin_once(timeout_sec=0.2)

    try:
        if len(args) not in (1, 3):
            node.get_logger().info("TF_Monitor: usage: tf2_monitor framea frameb")
            return 255
        monitor = TFMonitor(node, *args[1:3])
        executor.add_node(node)
        spinner = threading.Thread(target=spin, daemon=True)
        spinner.start()
        if monitor.specific:
            monitor.wait_for_chain()
        monitor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        stop.set()
        # Executor and node are destroyed only once nothing spins them. A SIGTERM can land
        # between the thread's creation and its start (seen on a loaded machine): nothing to
        # wait for then.
        if spinner is not None and spinner.ident is not None:
            spinner.join(timeout=5.0)
        if spinner is None or not spinner.is_alive():
            executor.shutdown(timeout_sec=2.0)
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
