"""Exercise: patrol the waypoints of each route from /patrol_route with Nav2's BasicNavigator."""

import rclpy
from geometry_msgs.msg import PoseStamped
from nav2_simple_commander.robot_navigator import BasicNavigator
from nav_msgs.msg import Path
from rclpy.executors import ExternalShutdownException
from rclpy.qos import DurabilityPolicy, QoSProfile


class RouteInbox:
    """The routes published on /patrol_route (latched), oldest first."""

    def __init__(self, navigator):
        self.navigator = navigator
        self.routes = []
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        navigator.create_subscription(Path, "/patrol_route", self.routes.append, latched)

    def next_route(self):
        """Wait for the next route: its waypoints, PoseStamped in the map frame."""
        while not self.routes:
            rclpy.spin_once(self.navigator, timeout_sec=0.2)
        return list(self.routes.pop(0).poses)


def start_pose(navigator):
    """Where the robot starts: the map's origin, facing +x."""
    pose = PoseStamped()
    pose.header.frame_id = "map"
    pose.header.stamp = navigator.get_clock().now().to_msg()
    # TODO 1: the position (0, 0) and an orientation facing +x (a quaternion: w = 1.0).
    return pose


def patrol(navigator, waypoints):
    """Drive to each waypoint in turn; say so once the robot is at the last."""
    # TODO 3: send the waypoints to Nav2 (navigator.followWaypoints), then loop until
    #         navigator.isTaskComplete() says the task is over. Then read
    #         navigator.getResult() (import TaskResult to compare it) and print a line
    #         that starts with "Patrol finished".
    print(f"Got a route of {len(waypoints)} waypoints (the patrol is yours to write)")


def main():
    rclpy.init()
    navigator = BasicNavigator(node_name="patrol")
    inbox = RouteInbox(navigator)
    try:
        # TODO 2: tell amcl where the robot starts (navigator.setInitialPose with
        #         start_pose(navigator)), then wait until Nav2 is active.
        while rclpy.ok():
            waypoints = inbox.next_route()
            patrol(navigator, waypoints)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        navigator.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
