"""Push an edited camera pose to the coordinate_transform node as ROS parameters.

Uses the node's ``set_parameters`` service with ``call_async``, so the viser
callback that triggered it never waits; a slider drag is coalesced by a
:class:`LatestWorker` to a few calls a second.
"""

from __future__ import annotations

from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters
from rclpy.node import Node

from app.scene.frames import CameraPose
from app.scene.latest import LatestWorker
from app.scene.qos import SCENE_CALLBACK_GROUP

TARGET_NODE = "/coordinate_transform"
# CameraPose field -> parameter name on the node
PARAM_NAMES: dict[str, str] = {
    "x": "camera_x",
    "y": "camera_y",
    "z": "camera_z",
    "roll": "camera_roll",
    "pitch": "camera_pitch",
    "yaw": "camera_yaw",
}


def pose_parameters(pose: CameraPose, names: dict[str, str] = PARAM_NAMES) -> list[Parameter]:
    """The SetParameters request body for ``pose`` (all doubles)."""
    return [
        Parameter(
            name=param,
            value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=float(value)),
        )
        for field, param in names.items()
        for value in (getattr(pose, field),)
    ]


class CameraParamSync:
    def __init__(self, node: Node, target: str = TARGET_NODE) -> None:
        self._node = node
        self._target = target
        self._client = node.create_client(
            SetParameters, f"{target}/set_parameters", callback_group=SCENE_CALLBACK_GROUP
        )
        self.status = ""
        self._worker = LatestWorker("camera-params", self._send, 3.0)

    def push(self, pose: CameraPose) -> None:
        self._worker.offer(pose)

    def _send(self, pose: CameraPose) -> None:
        if not self._client.service_is_ready():
            self.status = (
                f"`{self._target}` is not running: the pose is only changed here in the "
                "3D view. Start coordinate_transform to send it as parameters."
            )
            return
        request = SetParameters.Request(parameters=pose_parameters(pose))
        future = self._client.call_async(request)
        future.add_done_callback(self._on_result)
        self.status = f"Sending the pose to `{self._target}`…"

    def _on_result(self, future) -> None:
        try:
            results = future.result().results
        except Exception as exc:  # the service vanished mid-call
            self.status = f"⚠️ setting parameters failed: {exc}"
            return
        failed = [r.reason for r in results if not r.successful]
        if failed:
            self.status = f"⚠️ `{self._target}` refused: {'; '.join(failed)}"
        else:
            names = ", ".join(PARAM_NAMES.values())
            self.status = f"✓ `{self._target}` parameters set ({names})."

    def close(self) -> None:
        self._worker.stop()
        self._node.destroy_client(self._client)
