"""What the 3D layers drawn on the floor of a message's TF frame share (a map, a path, particles).

rviz draws a map, a planned path and amcl's particles where TF puts the
frame named in the message's header. These layers do the same: the drawing
hangs under the TF view's node of that frame (``/tf_view/frames/<frame>``),
so it moves with the frame, and ``describe()`` says, at every refresh, when
TF does not know the frame (yet): then the drawing sits at the Fixed Frame's
origin. Each layer follows one topic picked in its row (``select``), takes
its newest message on a worker (``LatestWorker``) and draws there; the
subscription matches what the publishers offer, latched ones included, so a
map or a plan published once still arrives when the topic is picked later.

Threads: the executor offers messages to the worker; the worker draws
(``draw`` of the subclass, which ends with ``drawn`` or ``nothing_drawn``);
the UI thread selects topics and reads ``describe()``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import viser
from rclpy.node import Node
from rclpy.subscription import Subscription

from app.ros.qos import matching_qos
from app.scene.latest import LatestWorker
from app.scene.qos import SCENE_CALLBACK_GROUP
from app.scene.tf_view import TF_PATH, scene_name
from app.scene.topic_picker import NONE

if TYPE_CHECKING:
    from typing import Literal, TypedDict

    import numpy as np
    import numpy.typing as npt
    from typing_extensions import NotRequired, Unpack

    class _ImageArgs(TypedDict):
        """viser's ``add_image`` arguments after the name (``show_image`` passes them on)."""

        image: np.ndarray
        render_width: float
        render_height: float
        format: NotRequired[Literal["auto", "png", "jpeg"]]
        jpeg_quality: NotRequired[int | None]
        cast_shadow: NotRequired[bool]
        receive_shadow: NotRequired[bool | float]
        scale: NotRequired[float | tuple[float, float, float]]
        wxyz: NotRequired[tuple[float, float, float, float] | np.ndarray]
        position: NotRequired[tuple[float, float, float] | np.ndarray]
        visible: NotRequired[bool]


def frame_of(header_frame: str) -> str:
    """A header's frame_id as TF names it (no leading slash, no spaces)."""
    return header_frame.strip().lstrip("/")


class FramedLayer:
    """One topic's newest message drawn under its frame; subclasses implement ``draw``."""

    NODE_NAME = "layer"  # the scene node's name under its frame
    LATCHED = True  # ask for a latched subscription whenever every publisher offers one
    MSG_TYPE: type | None = None  # the generated message class the default ``subscribe`` takes

    def __init__(
        self,
        node: Node,
        server: viser.ViserServer,
        worker_name: str,
        max_hz: float,
        frame_known: Callable[[str], bool] | None = None,
    ) -> None:
        self._node = node
        self._server = server
        self._frame_known = frame_known or (lambda _frame: True)
        self._subscription: Subscription | None = None
        self._handle: Any = None
        self._path = ""
        self.topic = NONE
        self.note = ""
        self._frame: str | None = None  # the drawing's frame; None: nothing drawn
        self.worker = LatestWorker(worker_name, self.draw, max_hz)

    # --- UI thread ---
    def select(self, topic: str) -> None:
        """Draw ``topic`` from now on ("(none)": nothing)."""
        if topic == self.topic:
            return
        self.topic = topic
        if self._subscription is not None:
            self._node.destroy_subscription(self._subscription)
            self._subscription = None
        self.worker.reset()
        self.forget()
        if topic != NONE:
            self._subscription = self.subscribe(topic)

    def subscribe(self, topic: str) -> Subscription:
        """The subscription for ``topic``; by default of ``MSG_TYPE``, messages to the worker."""
        qos = matching_qos(self._node, topic, depth=1, latched=self.LATCHED)
        return self._node.create_subscription(
            self.MSG_TYPE, topic, self.worker.offer, qos, callback_group=SCENE_CALLBACK_GROUP
        )

    def forget(self) -> None:
        """Take the drawing away and say nothing (the topic changed)."""
        self.remove_drawing()
        self.note = ""
        self._frame = None

    def close(self) -> None:
        self.select(NONE)
        self.worker.stop()

    def describe(self) -> str:
        """What was drawn and where; asked again at each refresh (TF may bring the frame later)."""
        note, frame = self.note, self._frame
        if frame is None:
            return note
        if not frame or not self._frame_known(frame):
            return f"{note}, ⚠️ frame `{frame or '(empty)'}` is not on TF: drawn at the origin"
        return f"{note}, in `{frame}`"

    # --- worker thread ---
    def draw(self, msg: object) -> None:
        raise NotImplementedError

    def scene_path(self, frame: str) -> str:
        """Where the drawing of a message in ``frame`` goes; an old drawing elsewhere goes."""
        parent = f"{TF_PATH}/frames/{scene_name(frame)}" if frame else TF_PATH
        path = f"{parent}/{self.NODE_NAME}"
        if path != self._path:
            self.remove_drawing()  # the topic moved to another frame
            self._path = path
        return path

    def show_segments(
        self,
        frame: str,
        segments: npt.NDArray[np.float32],
        colour: tuple[int, int, int],
        thickness: float,
    ) -> None:
        """Line segments (N, 2, 3) under ``frame``: updated in place when their count holds."""
        path = self.scene_path(frame)
        handle = self._handle
        if handle is None or len(handle.points) != len(segments):
            self.remove_drawing()
            self._handle = self._server.scene.add_line_segments(
                path, segments, colour, thickness=thickness, thickness_units="screen"
            )
        else:
            handle.points = segments

    def show_image(self, frame: str, **image: Unpack[_ImageArgs]) -> None:
        """A picture laid under ``frame`` (viser's ``add_image`` arguments)."""
        path = self.scene_path(frame)
        self._handle = self._server.scene.add_image(path, **image)

    def drawn(self, frame: str, note: str) -> None:
        self._frame = frame
        self.note = note

    def nothing_drawn(self, note: str) -> None:
        """A message that cannot be drawn (or holds nothing): the old drawing goes, say why."""
        self.remove_drawing()
        self._frame = None
        self.note = note

    def remove_drawing(self) -> None:
        handle, self._handle = self._handle, None
        if handle is not None:
            handle.remove()
