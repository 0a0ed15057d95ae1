"""Accepted: the motion update on a numpy array of particles, noise drawn for all at once, the
step read from the odometry through a 2D rotation instead of atan2 of the angles' difference."""

import numpy as np
import rclpy
from geometry_msgs.msg import Pose, PoseArray
from nav_msgs.msg import Odometry
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

ALPHA = np.array([0.05, 0.01, 0.02, 0.01])
rng = np.random.default_rng()


def yaw(q):
    return np.arctan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y**2 + q.z**2))


def wrap(a):
    return np.arctan2(np.sin(a), np.cos(a))


class Mover(Node):
    def __init__(self):
        super().__init__("particle_update")
        self.cloud = np.zeros((0, 3))
        self.frame = "map"
        self.odom = None
        self.pub = self.create_publisher(PoseArray, "/particles_moved", 10)
        self.create_subscription(Odometry, "/odom", self.on_odom, 10)
        self.create_subscription(PoseArray, "/particles", self.on_cloud, 10)

    def on_cloud(self, msg):
        self.frame = msg.header.frame_id
        self.cloud = np.array(
            [[p.position.x, p.position.y, yaw(p.orientation)] for p in msg.poses]
        ).reshape(-1, 3)

    def on_odom(self, msg):
        p = msg.pose.pose
        now = np.array([p.position.x, p.position.y, yaw(p.orientation)])
        before, self.odom = self.odom, now
        if before is None or len(self.cloud) == 0:
            return
        # The step in the robot's old frame: rotate the world step by minus the old yaw.
        c, s = np.cos(before[2]), np.sin(before[2])
        dx, dy = now[0] - before[0], now[1] - before[1]
        fx, fy = c * dx + s * dy, -s * dx + c * dy
        rot1, trans = np.arctan2(fy, fx), np.hypot(fx, fy)
        rot2 = wrap(now[2] - before[2] - rot1)
        a1, a2, a3, a4 = ALPHA
        n = len(self.cloud)
        r1 = rng.normal(rot1, np.sqrt(a1 * rot1**2 + a2 * trans**2), n)
        t = rng.normal(trans, np.sqrt(a3 * trans**2 + a4 * (rot1**2 + rot2**2)), n)
        r2 = rng.normal(rot2, np.sqrt(a1 * rot2**2 + a2 * trans**2), n)
        heading = self.cloud[:, 2] + r1
        self.cloud = np.column_stack(
            [
                self.cloud[:, 0] + t * np.cos(heading),
                self.cloud[:, 1] + t * np.sin(heading),
                wrap(heading + r2),
            ]
        )
        out = PoseArray()
        out.header.stamp, out.header.frame_id = msg.header.stamp, self.frame
        for x, y, th in self.cloud:
            pose = Pose()
            pose.position.x, pose.position.y = float(x), float(y)
            pose.orientation.z, pose.orientation.w = float(np.sin(th / 2)), float(np.cos(th / 2))
            out.poses.append(pose)
        self.pub.publish(out)


def main():
    rclpy.init()
    node = Mover()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
