"""Stamped points and poses (PointStamped, PoseStamped) drawn in their own frame.

Every such topic on the graph is followed automatically (up to a limit): the
coordinate-transform lesson publishes the same object in the camera frame
and in the base frame, and when the camera pose is right the two spheres
coincide in the 3D view.
"""

from __future__ import annotations

import viser
from geometry_msgs.msg import PointStamped, PoseStamped
from rclpy.node import Node

from app.ros.graph import GraphSnapshot
from app.scene import topic_picker as picker
from app.scene.follow import TopicFollower
from app.scene.frames import scene_path_for_frame
from app.scene.latest import LatestWorker
from app.scene.transforms import ros_to_wxyz

MAX_TOPICS = 8
LABEL_LIFT_M = 0.05  # a name above its point
LABEL_ROW_M = 0.035  # and the next topic's name this much higher
_COLOURS = ((230, 50, 50), (50, 120, 230), (40, 170, 60), (200, 120, 20), (150, 60, 200))


def _leaf(topic: str) -> str:
    return "".join(ch if ch.isalnum() else "_" for ch in topic.strip("/")) or "topic"


class _StampedTopic:
    def __init__(
        self,
        layer: StampedLayer,
        topic: str,
        is_pose: bool,
        colour: tuple[int, int, int],
        slot: int = 0,
    ) -> None:
        self.topic = topic
        self.slot = slot  # which row its name takes
        self.is_pose = is_pose
        self.colour = colour
        self.handle: viser.FrameHandle | viser.IcosphereHandle | None = None
        self.path = ""
        self.last = ""
        self.worker = LatestWorker(f"stamped{_leaf(topic)}", self._draw, 10.0)
        self._layer = layer
        msg_type = PoseStamped if is_pose else PointStamped
        self._follower = TopicFollower(layer.node, self.worker, msg_type, qos=10)
        self._follower.select(topic)

    def _draw(self, msg: PoseStamped | PointStamped) -> None:
        parent, known = scene_path_for_frame(msg.header.frame_id, self.topic)
        path = f"{parent}/stamped/{_leaf(self.topic)}"
        if self.is_pose:
            p, o = msg.pose.position, msg.pose.orientation
            position, wxyz = (p.x, p.y, p.z), ros_to_wxyz(o.x, o.y, o.z, o.w)
        else:
            p = msg.point
            position, wxyz = (p.x, p.y, p.z), (1.0, 0.0, 0.0, 0.0)
        scene = self._layer.scene
        handle = self.handle
        if handle is None or path != self.path:
            if handle is not None:
                handle.remove()
            if self.is_pose:
                handle = scene.add_frame(path, axes_length=0.1, axes_radius=0.005)
            else:
                handle = scene.add_icosphere(path, radius=0.025, color=self.colour)
            # Each topic's name a row higher: the lesson's points coincide when they are
            # right (the object seen from the camera, from the base, the gripper on it).
            lift = LABEL_LIFT_M + LABEL_ROW_M * self.slot
            scene.add_label(f"{path}/label", self.topic, position=(0.0, 0.0, lift))
            self.handle, self.path = handle, path
        handle.position = position
        handle.wxyz = wxyz
        where = "" if known else " (unknown frame: drawn at base_link)"
        self.last = (
            f"`{self.topic}` ({p.x:+.3f}, {p.y:+.3f}, {p.z:+.3f}) m in "
            f"`{msg.header.frame_id or '(empty)'}`{where}"
        )

    def close(self) -> None:
        self._follower.close()
        if self.handle is not None:
            self.handle.remove()


class StampedLayer:
    def __init__(self, node: Node, server: viser.ViserServer) -> None:
        self.node = node
        self.scene = server.scene
        self._followers: dict[str, _StampedTopic] = {}

    def refresh(self, graph: GraphSnapshot | None) -> None:
        """Follow every new published stamped point/pose topic, and stop drawing those whose
        publishers all left (UI thread): a stopped node's point stood on, looking current
        (a learner compared a moving arm's point with a tf2 one stopped a step before)."""
        if graph is None:
            return
        self.forget_unpublished(graph)
        points = picker.drawable_topics(graph, picker.POINT_TYPES)
        poses = picker.drawable_topics(graph, picker.POSE_TYPES)
        for topic, is_pose in [(t, False) for t in points] + [(t, True) for t in poses]:
            if topic in self._followers or len(self._followers) >= MAX_TOPICS:
                continue
            if graph.publishers(topic) == 0:  # a subscriber alone lists it: nothing to draw
                continue
            slot = min(set(range(MAX_TOPICS)) - {f.slot for f in self._followers.values()})
            colour = _COLOURS[slot % len(_COLOURS)]
            self._followers[topic] = _StampedTopic(self, topic, is_pose, colour, slot)

    def forget_unpublished(self, graph: GraphSnapshot) -> None:
        """Stop drawing the points and poses nobody publishes now (UI thread)."""
        for topic in [t for t in self._followers if graph.publishers(t) == 0]:
            self._followers.pop(topic).close()

    def describe(self) -> str:
        lines = [f.last for f in self._followers.values() if f.last]
        if not lines:
            return ""
        return "**Stamped points and poses** (drawn in their frame):\n\n" + "\n".join(
            f"- {line}" for line in lines
        )

    def close(self) -> None:
        for follower in self._followers.values():
            follower.close()
        self._followers.clear()
