"""TransformListener: fill a Buffer from /tf and /tf_static.

Given a node, it subscribes on that node (spun by whoever spins it, or by a
thread of its own with ``spin_thread=True``). Without one it makes a node of
its own and spins it in a thread, as the C++ listener does.
"""

from __future__ import annotations

import uuid
from threading import Thread

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile
from rclpy.serialization import deserialize_message
from tf2_msgs.msg import TFMessage

from tf2_ros._wire import decode_tf_message
from tf2_ros.buffer import Buffer


class TransformListener:
    """Subscribes /tf (volatile) and /tf_static (transient local), both keep last 100."""

    def __init__(
        self,
        buffer: Buffer,
        node: Node | None = None,
        *,
        spin_thread: bool = False,
        qos: QoSProfile | int | None = None,
        static_qos: QoSProfile | int | None = None,
    ) -> None:
        if qos is None:
            qos = QoSProfile(
                depth=100, durability=DurabilityPolicy.VOLATILE, history=HistoryPolicy.KEEP_LAST
            )
        if static_qos is None:
            static_qos = QoSProfile(
                depth=100,
                durability=DurabilityPolicy.TRANSIENT_LOCAL,
                history=HistoryPolicy.KEEP_LAST,
            )
        self._own_node = node is None
        if node is None:
            node = Node(f"transform_listener_impl_{uuid.uuid4().hex[:12]}")
            spin_thread = True
        self.buffer = buffer
        self.node = node
        # Reentrant: a callback may wait for a transform while these keep arriving.
        self.group = ReentrantCallbackGroup()
        # The bytes are read here (tf2_ros._wire) unless a subclass handles messages itself
        # or the buffer's set_transform is someone else's: then rclpy's messages, as upstream.
        raw = (
            type(self).callback is TransformListener.callback
            and type(self).static_callback is TransformListener.static_callback
            and type(buffer).set_transform is Buffer.set_transform
            and type(buffer).set_transform_static is Buffer.set_transform_static
        )
        self.tf_sub = node.create_subscription(
            TFMessage,
            "/tf",
            self._raw_callback if raw else self.callback,
            qos,
            callback_group=self.group,
            raw=raw,
        )
        self.tf_static_sub = node.create_subscription(
            TFMessage,
            "/tf_static",
            self._raw_static_callback if raw else self.static_callback,
            static_qos,
            callback_group=self.group,
            raw=raw,
        )
        if spin_thread:
            self.executor = SingleThreadedExecutor()

            def run_func() -> None:
                self.executor.add_node(self.node)
                try:
                    self.executor.spin()
                except Exception:
                    pass
                self.executor.remove_node(self.node)

            # Not a daemon: the thread ends when ROS shuts down (the executor stops then).
            self.dedicated_listener_thread = Thread(target=run_func)
            self.dedicated_listener_thread.start()

    def __del__(self) -> None:
        try:
            if hasattr(self, "dedicated_listener_thread") and hasattr(self, "executor"):
                self.executor.shutdown()
                self.dedicated_listener_thread.join(timeout=2.0)
            self.unregister()
        except Exception:
            pass

    def unregister(self) -> None:
        """Stop listening (destroys both subscriptions)."""
        self.node.destroy_subscription(self.tf_sub)
        self.node.destroy_subscription(self.tf_static_sub)

    def _raw_callback(self, data: bytes) -> None:
        entries = decode_tf_message(data)
        if entries is None:
            self.callback(deserialize_message(data, TFMessage))
        else:
            self.buffer._set_entries(entries, "default_authority", False)

    def _raw_static_callback(self, data: bytes) -> None:
        entries = decode_tf_message(data)
        if entries is None:
            self.static_callback(deserialize_message(data, TFMessage))
        else:
            self.buffer._set_entries(entries, "default_authority", True)

    def callback(self, data: TFMessage) -> None:
        who = "default_authority"
        for transform in data.transforms:
            self.buffer.set_transform(transform, who)

    def static_callback(self, data: TFMessage) -> None:
        who = "default_authority"
        for transform in data.transforms:
            self.buffer.set_transform_static(transform, who)
