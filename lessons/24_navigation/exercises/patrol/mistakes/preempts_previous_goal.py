"""Mistake: Sends every goal at once: each new goToPose replaces the one before."""

import rclpy
from geometry_msgs.msg import PoseStamped
from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult
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
    pose.pose.position.x = 0.0
    pose.pose.position.y = 0.0
    pose.pose.orientation.w = 1.0
    return pose


def patrol(navigator, waypoints):
    """Drive to each waypoint in turn; say so once the robot is at the last."""
    for i, waypoint in enumerate(waypoints):
        if not navigator.goToPose(waypoint):
            print(f"Waypoint {i + 1} was rejected")
    while not navigator.isTaskComplete():
        pass
    result = navigator.getResult()
    if result != TaskResult.SUCCEEDED:
        print(f"The patrol did not succeed: {result}")
    print(f"Patrol finished: {result}")


def main():
    rclpy.init()
    navigator = BasicNavigator(node_name="patrol")
    inbox = RouteInbox(navigator)
    try:
        navigator.setInitialPose(start_pose(navigator))
        navigator.waitUntilNav2Active()
        while rclpy.ok():
            waypoints = inbox.next_route()
            print(f"Got a route of {len(waypoints)} waypoints")
            patrol(navigator, waypoints)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        navigator.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
