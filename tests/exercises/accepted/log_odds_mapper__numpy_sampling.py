"""Accepted: the log-odds map in numpy arrays, a beam's cells found by sampling points along
it (every quarter of a cell) instead of Bresenham's line, the probabilities compared."""

import math

import numpy as np
import rclpy
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import OccupancyGrid
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import LaserScan

SHAPE = (40, 60)  # rows, columns
RES, ORIGIN = 0.1, np.array([-3.0, -2.0])


class Mapper(Node):
    def __init__(self):
        super().__init__("log_odds_mapper")
        self.l = np.zeros(SHAPE)
        self.pose = None
        qos = QoSProfile(
            depth=1,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        self.out = self.create_publisher(OccupancyGrid, "/map", qos)
        self.create_subscription(LaserScan, "/scan", self.on_scan, 10)
        self.create_subscription(PoseStamped, "/robot_pose", self.on_pose, 10)

    def on_pose(self, msg):
        q = msg.pose.orientation
        yaw = 2.0 * math.atan2(q.z, q.w)
        self.pose = np.array([msg.pose.position.x, msg.pose.position.y]), yaw

    def on_scan(self, msg):
        if self.pose is None:
            return
        xy, yaw = self.pose
        r = np.asarray(msg.ranges, dtype=float)
        angles = yaw + msg.angle_min + np.arange(len(r)) * msg.angle_increment
        ok = np.isfinite(r) & (r >= msg.range_min) & (r <= msg.range_max)
        r, angles = r[ok], angles[ok]
        direction = np.stack([np.cos(angles), np.sin(angles)], axis=1)
        ends = xy + r[:, None] * direction
        end_cells = np.floor((ends - ORIGIN) / RES).astype(int)
        # Points every quarter cell from the robot to just before the end of each beam.
        steps = np.arange(0.0, r.max(), RES / 4)
        points = xy + steps[None, :, None] * direction[:, None, :]
        before_end = steps[None, :] < r[:, None]
        cells = np.floor((points[before_end] - ORIGIN) / RES).astype(int)
        hit = self.inside(end_cells)
        hit_set = {tuple(c) for c in end_cells[hit]}
        crossed = {tuple(c) for c in cells[self.inside(cells)]} - hit_set
        for group, change in ((crossed, -0.4), (hit_set, 0.85)):
            if group:
                cols, rows = np.array(sorted(group)).T
                self.l[rows, cols] = np.clip(self.l[rows, cols] + change, -2.0, 3.5)
        self.publish(msg.header.stamp)

    @staticmethod
    def inside(cells):
        return (
            (cells[:, 0] >= 0)
            & (cells[:, 0] < SHAPE[1])
            & (cells[:, 1] >= 0)
            & (cells[:, 1] < SHAPE[0])
        )

    def publish(self, stamp):
        p = 1.0 - 1.0 / (1.0 + np.exp(self.l))
        values = np.where(p > 0.65, 100, np.where(p < 0.25, 0, -1)).astype(np.int8)
        grid = OccupancyGrid()
        grid.header.frame_id, grid.header.stamp = "map", stamp
        grid.info.resolution = RES
        grid.info.height, grid.info.width = SHAPE
        grid.info.origin.position.x, grid.info.origin.position.y = ORIGIN
        grid.info.origin.orientation.w = 1.0
        grid.data = values.ravel().tolist()  # row after row: numpy's own order
        self.out.publish(grid)


def main():
    rclpy.init()
    node = Mapper()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
