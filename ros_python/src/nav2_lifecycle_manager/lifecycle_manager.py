"""lifecycle_manager: Nav2's lifecycle manager, which brings the navigation servers up in order.

``ros2 run nav2_lifecycle_manager lifecycle_manager --ros-args -p node_names:="[planner_server,
controller_server, bt_navigator]" -p autostart:=true`` configures and then
activates each node in ``node_names`` in that order (through their
``<node>/change_state`` services), and offers

- ``<this node>/manage_nodes`` (nav2_msgs/srv/ManageLifecycleNodes):
  ``STARTUP`` (configure + activate, in order), ``PAUSE`` (deactivate, in
  reverse order), ``RESUME`` (activate), ``RESET`` (deactivate + cleanup),
  ``SHUTDOWN`` (deactivate, cleanup, shut down), ``CONFIGURE``, ``CLEANUP``;
- ``<this node>/is_active`` (std_srvs/srv/Trigger): ``success`` true while
  the managed nodes are active.

The log lines are Nav2's ("Starting managed nodes bringup...",
"Configuring planner_server", "Managed nodes are active"...). Not here: the
bond connections that notice a crashed server (``bond_timeout``).
"""

from __future__ import annotations

import sys
import threading
from typing import Any

from lifecycle_msgs.msg import State, Transition
from lifecycle_msgs.srv import ChangeState, GetState
from nav2_msgs.srv import ManageLifecycleNodes
from nav2_util.server_main import spin_server
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from rclpy.client import Client
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_srvs.srv import Trigger

LABELS = {
    Transition.TRANSITION_CONFIGURE: "Configuring ",
    Transition.TRANSITION_ACTIVATE: "Activating ",
    Transition.TRANSITION_DEACTIVATE: "Deactivating ",
    Transition.TRANSITION_CLEANUP: "Cleaning up ",
    Transition.TRANSITION_UNCONFIGURED_SHUTDOWN: "Shutting down ",
}
GOAL_STATE = {
    Transition.TRANSITION_CONFIGURE: State.PRIMARY_STATE_INACTIVE,
    Transition.TRANSITION_ACTIVATE: State.PRIMARY_STATE_ACTIVE,
    Transition.TRANSITION_DEACTIVATE: State.PRIMARY_STATE_INACTIVE,
    Transition.TRANSITION_CLEANUP: State.PRIMARY_STATE_UNCONFIGURED,
    Transition.TRANSITION_UNCONFIGURED_SHUTDOWN: State.PRIMARY_STATE_FINALIZED,
}
ACTIVE, INACTIVE, UNCONFIGURED, FINALIZED, UNKNOWN = range(5)
BOLD_BLUE = "\x1b[34m\x1b[1m{}\x1b[0m\x1b[0m"


class LifecycleManager(Node):
    def __init__(self, **kwargs: Any) -> None:
        super().__init__("lifecycle_manager", **kwargs)
        self.get_logger().info("Creating")
        self.declare_parameter("node_names", Parameter.Type.STRING_ARRAY)
        self.declare_parameter("autostart", False)
        self.declare_parameter("bond_timeout", 4.0)
        self.declare_parameter("service_timeout", 10.0)
        names = self.get_parameter_or("node_names", Parameter("node_names", value=[])).value
        self.node_names = [str(n) for n in names or []]
        self.autostart = bool(self.get_parameter("autostart").value)
        self.state = UNCONFIGURED
        self.busy = threading.Lock()
        self.lc_clients: dict[str, tuple[Client, Client]] = {}
        self.group = ReentrantCallbackGroup()
        services = MutuallyExclusiveCallbackGroup()
        self.create_service(
            ManageLifecycleNodes,
            f"{self.get_name()}/manage_nodes",
            self.on_manage_nodes,
            callback_group=services,
        )
        self.create_service(
            Trigger, f"{self.get_name()}/is_active", self.on_is_active, callback_group=self.group
        )
        self.message("Creating and initializing lifecycle service clients")
        for name in self.node_names:
            self.lc_clients[name] = (
                self.create_client(ChangeState, f"{name}/change_state", callback_group=self.group),
                self.create_client(GetState, f"{name}/get_state", callback_group=self.group),
            )
        if self.autostart:
            self.init_timer = self.create_timer(0.0, self.on_autostart, callback_group=services)

    def message(self, text: str) -> None:
        self.get_logger().info(BOLD_BLUE.format(text))

    def on_autostart(self) -> None:
        self.init_timer.cancel()
        self.startup()

    # --- the services ---
    def on_is_active(self, request: Any, response: Any) -> Any:
        response.success = self.state == ACTIVE
        return response

    def on_manage_nodes(self, request: Any, response: Any) -> Any:
        command = request.command
        R = ManageLifecycleNodes.Request
        actions = {
            R.STARTUP: self.startup,
            R.CONFIGURE: self.configure,
            R.CLEANUP: self.cleanup,
            R.RESET: self.reset,
            R.SHUTDOWN: self.shutdown,
            R.PAUSE: self.pause,
            R.RESUME: self.resume,
        }
        action = actions.get(command)
        if action is None:
            self.get_logger().error(f"Unknown command {command}")
            response.success = False
        else:
            response.success = bool(action())
        return response

    # --- transitions ---
    def wait_call(self, client: Client, request: Any, timeout: float) -> Any:
        if not client.wait_for_service(timeout_sec=timeout):
            raise TimeoutError(f"{client.srv_name} service not available")
        done = threading.Event()
        future = client.call_async(request)
        future.add_done_callback(lambda _f: done.set())
        if not done.wait(timeout):
            raise TimeoutError(f"{client.srv_name} did not answer")
        return future.result()

    def change_state_for_node(self, name: str, transition: int) -> bool:
        self.message(LABELS[transition] + name)
        change, get = self.lc_clients[name]
        timeout = float(self.get_parameter("service_timeout").value)
        try:
            self.get_logger().info(f"Waiting for service {name}/get_state...")
            ok = self.wait_call(
                change, ChangeState.Request(transition=Transition(id=transition)), timeout
            )
            current = self.wait_call(get, GetState.Request(), timeout)
            if ok.success and current.current_state.id == GOAL_STATE[transition]:
                return True
        except TimeoutError as exc:
            self.get_logger().error(f"Failed to change state for node: {name}. Exception: {exc}.")
            return False
        self.get_logger().error(f"Failed to change state for node: {name}")
        return False

    def change_state_for_all(self, transition: int, hard_change: bool = False) -> bool:
        forward = transition in (Transition.TRANSITION_CONFIGURE, Transition.TRANSITION_ACTIVATE)
        names = self.node_names if forward else list(reversed(self.node_names))
        for name in names:
            if not self.change_state_for_node(name, transition) and not hard_change:
                return False
        return True

    def startup(self) -> bool:
        with self.busy:
            self.message("Starting managed nodes bringup...")
            if not self.change_state_for_all(
                Transition.TRANSITION_CONFIGURE
            ) or not self.change_state_for_all(Transition.TRANSITION_ACTIVATE):
                self.get_logger().error("Failed to bring up all requested nodes. Aborting bringup.")
                self.state = UNKNOWN
                return False
            self.message("Managed nodes are active")
            self.state = ACTIVE
            return True

    def configure(self) -> bool:
        with self.busy:
            self.message("Configuring managed nodes...")
            if not self.change_state_for_all(Transition.TRANSITION_CONFIGURE):
                self.get_logger().error(
                    "Failed to configure all requested nodes. Aborting bringup."
                )
                self.state = UNKNOWN
                return False
            self.message("Managed nodes are now configured")
            self.state = INACTIVE
            return True

    def cleanup(self) -> bool:
        with self.busy:
            self.message("Cleaning up managed nodes...")
            if not self.change_state_for_all(Transition.TRANSITION_CLEANUP):
                self.get_logger().error("Failed to cleanup all requested nodes. Aborting cleanup.")
                self.state = UNKNOWN
                return False
            self.message("Managed nodes have been cleaned up")
            self.state = UNCONFIGURED
            return True

    def shutdown(self) -> bool:
        with self.busy:
            self.message("Shutting down managed nodes...")
            self.message("Deactivate, cleanup, and shutdown nodes")
            self.state = FINALIZED
            if self.all_in(State.PRIMARY_STATE_ACTIVE):
                self.change_state_for_all(Transition.TRANSITION_DEACTIVATE, True)
            if self.all_in(State.PRIMARY_STATE_INACTIVE):
                self.change_state_for_all(Transition.TRANSITION_CLEANUP, True)
            self.change_state_for_all(Transition.TRANSITION_UNCONFIGURED_SHUTDOWN, True)
            self.message("Managed nodes have been shut down")
            return True

    def all_in(self, state_id: int) -> bool:
        """Whether any managed node is in ``state_id`` (the transitions from there apply)."""
        timeout = float(self.get_parameter("service_timeout").value)
        for name in self.node_names:
            try:
                got = self.wait_call(self.lc_clients[name][1], GetState.Request(), timeout)
            except TimeoutError:
                continue
            if got.current_state.id == state_id:
                return True
        return False

    def reset(self) -> bool:
        with self.busy:
            self.message("Resetting managed nodes...")
            if not self.change_state_for_all(
                Transition.TRANSITION_DEACTIVATE
            ) or not self.change_state_for_all(Transition.TRANSITION_CLEANUP):
                self.get_logger().error("Failed to reset nodes: aborting reset")
                self.state = UNKNOWN
                return False
            self.message("Managed nodes have been reset")
            self.state = UNCONFIGURED
            return True

    def pause(self) -> bool:
        with self.busy:
            self.message("Pausing managed nodes...")
            if not self.change_state_for_all(Transition.TRANSITION_DEACTIVATE):
                self.get_logger().error("Failed to pause nodes: aborting pause")
                self.state = UNKNOWN
                return False
            self.message("Managed nodes have been paused")
            self.state = INACTIVE
            return True

    def resume(self) -> bool:
        with self.busy:
            self.message("Resuming managed nodes...")
            if not self.change_state_for_all(Transition.TRANSITION_ACTIVATE):
                self.get_logger().error("Failed to resume nodes: aborting resume")
                self.state = UNKNOWN
                return False
            self.message("Managed nodes are active")
            self.state = ACTIVE
            return True


def main(args: list[str] | None = None) -> int:
    return spin_server(LifecycleManager, args, "lifecycle_manager")


if __name__ == "__main__":
    sys.exit(main())
