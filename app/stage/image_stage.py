"""Camera images on stage: what the camera sends, and under it what a node made of it.

The images lesson's evidence: ``/camera/image_raw`` as ``image_publisher`` draws
it, and ``object_detector``'s picture with the ball it found circled
(``/object_detection/output``), each with its size, encoding and rate, as
``ros2 topic hz`` and rqt_image_view would show them. The pictures are
decoded and scaled in the scene's image workers, a few times a second; the
subscriptions exist only while this stage is shown.
"""

from __future__ import annotations

import viser
from rclpy.node import Node

from app.ros.graph import GraphSnapshot
from app.scene.images import ImageLayer
from app.scene.topic_picker import NONE
from app.ui import MarkdownView

IMAGE_TYPE = "sensor_msgs/msg/Image"
PANES = 2
NOTHING = (
    "_No camera image on the graph yet._ Start the step's camera node from its button "
    "(`image_publisher`, `video_publisher`): its pictures show here, and under them what "
    "a detector finds in them."
)


def image_topics(graph: GraphSnapshot) -> list[str]:
    """Image topics some node publishes, the camera's own first (a node's output after)."""
    found = [
        t.name for t in graph.topics if IMAGE_TYPE in t.types and t.publishers > t.own_publishers
    ]
    return sorted(found, key=lambda name: (not name.endswith("image_raw"), name))[:PANES]


class ImageStage:
    def __init__(self, gui: viser.GuiApi, node: Node) -> None:
        self._active = False
        self._box = gui.add_folder("Camera images", expand_by_default=True, visible=False)
        with self._box:
            self._note = MarkdownView(gui, NOTHING)
            self._captions: list[MarkdownView] = []
            self._layers: list[ImageLayer] = []
            for _ in range(PANES):  # each picture under its caption (topic, size, rate)
                self._captions.append(MarkdownView(gui, ""))
                self._layers.append(ImageLayer(node, gui, None, label=None))
                self._layers[-1].handle.visible = False

    def set_active(self, active: bool) -> None:
        self._active = active
        self._box.visible = active
        if not active:
            for layer in self._layers:
                layer.select(NONE)  # no subscription for pictures nobody sees

    def refresh(self, graph: GraphSnapshot) -> None:
        if not self._active:
            return
        topics = image_topics(graph)
        self._note.show(
            "What the camera sends, and what a node made of it (`ros2 run rqt_image_view "
            "rqt_image_view`)."
            if topics
            else NOTHING
        )
        for index, (layer, caption) in enumerate(zip(self._layers, self._captions, strict=True)):
            topic = topics[index] if index < len(topics) else NONE
            layer.select(topic)
            layer.handle.visible = topic != NONE
            caption.show(_caption(layer) if topic != NONE else "")

    def close(self) -> None:
        for layer in self._layers:
            layer.close()


def _caption(layer: ImageLayer) -> str:
    _received, drawn, rate, since = layer.worker.stats()
    text = f"**`{layer.topic}`**"
    if layer.info:
        text += f" · {layer.info}"
    if rate is not None and since is not None and since < 2.0:
        text += f" · {rate:.1f} Hz"
    elif not drawn:
        text += " · waiting for the first picture…"
    else:
        text += " · no new picture for a while"
    return text
