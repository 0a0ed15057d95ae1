"""Joint sliders in the browser: joint_state_publisher_gui's window, as a folder of the 3D view.

Upstream's GUI is a window of sliders, one per movable joint of the robot
description, that drive joint_state_publisher. Here the sliders are built
from the robot the 3D view has parsed; moving one publishes every slider's
value as a sensor_msgs/JointState on ``/joint_state_sliders``, the topic in
the ``source_list`` of the catalog's ``joint_state_publisher_gui``. The
publisher is made on the UI thread when the first robot with joints arrives
(an idle dashboard adds no JointState topic); slider callbacks run on the UI
thread too (posted intents) and only publish.
"""

from __future__ import annotations

import math

import viser
from rclpy.node import Node
from rclpy.publisher import Publisher
from sensor_msgs.msg import JointState

from app.scene.robot_model import SliderJoint
from app.ui import MarkdownView
from app.ui.loop import UiLoop

TOPIC = "/joint_state_sliders"
HINT = (
    "Start **joint_state_publisher_gui** (Nodes tab) or any joint_state_publisher with "
    f"`source_list:=['{TOPIC}']`; the sliders then move the robot."
)


class JointSliders:
    def __init__(self, gui: viser.GuiApi, ui: UiLoop, node: Node) -> None:
        self._gui = gui
        self._ui = ui
        self._node = node
        self._publisher: Publisher | None = None
        self._joints: tuple[SliderJoint, ...] = ()
        self._sliders: dict[str, viser.GuiSliderHandle] = {}
        self._folder = gui.add_folder("Joint sliders (joint_state_publisher_gui)")
        with self._folder:
            self._note = MarkdownView(gui, "No robot description yet.")

    def show(self, joints: tuple[SliderJoint, ...]) -> None:
        """One slider per joint of the newest robot (UI thread); unchanged robots keep theirs."""
        if joints == self._joints:
            return
        self._joints = joints
        if joints and self._publisher is None:
            self._publisher = self._node.create_publisher(JointState, TOPIC, 10)
        for slider in self._sliders.values():
            slider.remove()
        self._sliders.clear()
        with self._folder:
            for joint in joints:
                start = (
                    0.0 if joint.lower <= 0.0 <= joint.upper else (joint.lower + joint.upper) / 2
                )
                slider = self._gui.add_slider(
                    joint.name,
                    min=joint.lower,
                    max=joint.upper,
                    step=(joint.upper - joint.lower) / 200.0,
                    initial_value=start,
                )
                slider.on_update(self._ui.callback(self.publish))
                self._sliders[joint.name] = slider
        self._note.show(HINT if joints else "This robot has no movable joints.")

    def publish(self) -> None:
        """Every slider's value; a value that is not a finite number (forged) is left out."""
        names, positions = [], []
        for name, slider in self._sliders.items():
            try:
                value = float(slider.value)
            except (TypeError, ValueError):
                continue
            if math.isfinite(value):
                names.append(name)
                positions.append(value)
        msg = JointState()
        msg.header.stamp = self._node.get_clock().now().to_msg()
        msg.name, msg.position = names, positions
        if self._publisher is not None:
            self._publisher.publish(msg)

    def close(self) -> None:
        if self._publisher is not None:
            self._node.destroy_publisher(self._publisher)
