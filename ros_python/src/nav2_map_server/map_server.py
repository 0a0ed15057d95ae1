"""map_server: serves a map file as nav_msgs/OccupancyGrid, a lifecycle node as in Nav2.

``ros2 run nav2_map_server map_server --ros-args -p yaml_filename:=office.yaml``
starts it *unconfigured*, as every Nav2 server starts; then

- ``configure`` loads ``yaml_filename`` (when set) and creates the latched
  publisher on ``topic_name`` (``map``: reliable, transient local, depth 1,
  as ROS 1's latched topics), the service ``map_server/map``
  (nav_msgs/GetMap) and ``map_server/load_map`` (nav2_msgs/LoadMap);
- ``activate`` publishes the map (a late subscriber still gets it);
- ``load_map`` (while active) loads another file and publishes it, and
  answers with the map and a result code (``RESULT_SUCCESS``,
  ``RESULT_MAP_DOES_NOT_EXIST``, ``RESULT_INVALID_MAP_METADATA``,
  ``RESULT_INVALID_MAP_DATA``, ``RESULT_UNDEFINED_FAILURE``).

A file that does not load makes ``configure`` fail with the reason in the
log: the node stays unconfigured and running, ready for a corrected
``yaml_filename`` and another ``configure``. Parameters: ``yaml_filename``,
``topic_name`` (``map``), ``frame_id`` (``map``).
"""

from __future__ import annotations

import sys
from typing import Any

import rclpy
from lifecycle_msgs.msg import State
from nav2_msgs.srv import LoadMap
from nav2_util.lifecycle_node import LifecycleNode
from nav_msgs.msg import OccupancyGrid
from nav_msgs.srv import GetMap
from rclpy.executors import ExternalShutdownException
from rclpy.lifecycle import LifecycleState, TransitionCallbackReturn
from rclpy.lifecycle.publisher import LifecyclePublisher
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.service import Service

from nav2_map_server.map_io import LoadMapStatus, load_map_from_yaml

SERVICE_NAME = "map"
LOAD_MAP_SERVICE_NAME = "load_map"
LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
RESULTS = {
    LoadMapStatus.MAP_DOES_NOT_EXIST: LoadMap.Response.RESULT_MAP_DOES_NOT_EXIST,
    LoadMapStatus.INVALID_MAP_METADATA: LoadMap.Response.RESULT_INVALID_MAP_METADATA,
    LoadMapStatus.INVALID_MAP_DATA: LoadMap.Response.RESULT_INVALID_MAP_DATA,
    LoadMapStatus.LOAD_MAP_SUCCESS: LoadMap.Response.RESULT_SUCCESS,
}


class MapServer(LifecycleNode):
    def __init__(self, **kwargs: Any) -> None:
        super().__init__("map_server", **kwargs)
        self.get_logger().info("Creating")
        self.declare_parameter("yaml_filename", "")
        self.declare_parameter("topic_name", "map")
        self.declare_parameter("frame_id", "map")
        self.frame_id = "map"
        self.msg = OccupancyGrid()
        self.map_available = False
        self.occ_pub: LifecyclePublisher | None = None
        self.occ_service: Service | None = None
        self.load_map_service: Service | None = None

    # --- transitions ---
    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Configuring")
        yaml_filename = str(self.get_parameter("yaml_filename").value or "")
        topic_name = str(self.get_parameter("topic_name").value or "map")
        self.frame_id = str(self.get_parameter("frame_id").value or "map")
        if yaml_filename:
            response = LoadMap.Response()
            reason = self.load_map_response_from_yaml(yaml_filename, response)
            if reason:
                self.get_logger().error(
                    f"Failed to load map yaml file: {yaml_filename} ({reason}); "
                    "staying unconfigured: fix the file or yaml_filename and configure again"
                )
                return TransitionCallbackReturn.FAILURE
        else:
            service = LOAD_MAP_SERVICE_NAME
            self.get_logger().info(
                f"yaml-filename parameter is empty, set map through '{service}'-service"
            )
        prefix = self.get_name() + "/"
        self.occ_service = self.create_service(GetMap, prefix + SERVICE_NAME, self.get_map_callback)
        self.occ_pub = self.create_lifecycle_publisher(OccupancyGrid, topic_name, LATCHED)
        self.load_map_service = self.create_service(
            LoadMap, prefix + LOAD_MAP_SERVICE_NAME, self.load_map_callback
        )
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Activating")
        result = super().on_activate(state)  # enables the lifecycle publisher
        if self.map_available and self.occ_pub is not None:
            self.occ_pub.publish(self.msg)
        return result

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.get_logger().info("Deactivating")
        return super().on_deactivate(state)

    def release(self) -> None:
        if self.occ_pub is not None:
            self.destroy_lifecycle_publisher(self.occ_pub)
            self.occ_pub = None
        for service in (self.occ_service, self.load_map_service):
            if service is not None:
                self.destroy_service(service)
        self.occ_service = self.load_map_service = None
        self.map_available = False
        self.msg = OccupancyGrid()

    # --- services ---
    def _active(self) -> bool:
        return self._state_machine.current_state[0] == State.PRIMARY_STATE_ACTIVE

    def get_map_callback(self, request: GetMap.Request, response: GetMap.Response) -> Any:
        if not self._active():
            self.get_logger().warning("Received GetMap request but not in ACTIVE state, ignoring!")
            return response
        self.get_logger().info("Handling GetMap request")
        response.map = self.msg
        return response

    def load_map_callback(self, request: LoadMap.Request, response: LoadMap.Response) -> Any:
        if not self._active():
            self.get_logger().warning("Received LoadMap request but not in ACTIVE state, ignoring!")
            response.result = LoadMap.Response.RESULT_UNDEFINED_FAILURE
            return response
        self.get_logger().info("Handling LoadMap request")
        url = request.map_url
        if url.startswith("file://"):  # the service's documented URL form
            url = url[len("file://") :]
        reason = self.load_map_response_from_yaml(url, response)
        if reason:
            self.get_logger().error(f"LoadMap of '{request.map_url}' failed: {reason}")
        elif self.occ_pub is not None:
            self.occ_pub.publish(self.msg)
        return response

    def load_map_response_from_yaml(self, yaml_file: str, response: LoadMap.Response) -> str:
        """Load into ``self.msg`` and fill ``response``; '' on success, else the reason."""
        loaded = load_map_from_yaml(yaml_file)
        response.result = RESULTS[loaded.status]
        if not loaded.ok or loaded.map is None:
            return loaded.reason or loaded.status.name
        self.msg = loaded.map
        now = self.get_clock().now().to_msg()
        self.msg.info.map_load_time = now
        self.msg.header.frame_id = self.frame_id
        self.msg.header.stamp = now
        self.map_available = True
        response.map = self.msg
        return ""


def main(args: list[str] | None = None) -> int:
    node: MapServer | None = None
    try:
        try:
            rclpy.init(args=args)
        except Exception as exc:  # rcl refuses the arguments (e.g. a -p value YAML cannot read)
            print(f"map_server: error: {exc}", file=sys.stderr)
            return 1
        node = MapServer()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
