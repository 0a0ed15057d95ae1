"""Exercise: build a log-odds occupancy grid from /scan and /robot_pose, publish it on /map."""

import math

import rclpy
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import OccupancyGrid
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import QoSProfile
from sensor_msgs.msg import LaserScan

WIDTH, HEIGHT = 60, 40  # cells: columns along x, rows along y
RESOLUTION = 0.1  # metres per cell
ORIGIN_X, ORIGIN_Y = -3.0, -2.0  # the corner of cell (0, 0) in the map frame
HIT, MISS = 0.85, -0.4  # added to a cell's log-odds: a beam ends in it / passes through it
L_MIN, L_MAX = -2.0, 3.5  # a cell's log-odds stays between these
OCCUPIED_ABOVE = math.log(0.65 / 0.35)  # 0.62: probability above 0.65
FREE_BELOW = math.log(0.25 / 0.75)  # -1.10: probability below 0.25


def yaw_of(q):
    """The heading (rad) of a quaternion that turns about z only."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def line_cells(c0, r0, c1, r1):
    """The cells of the straight line from (c0, r0) to (c1, r1), both included (Bresenham)."""
    dc, dr = abs(c1 - c0), -abs(r1 - r0)
    sc, sr = (1 if c1 > c0 else -1), (1 if r1 > r0 else -1)
    err = dc + dr
    cells = []
    while True:
        cells.append((c0, r0))
        if c0 == c1 and r0 == r1:
            return cells
        e2 = 2 * err
        if e2 >= dr:
            err += dr
            c0 += sc
        if e2 <= dc:
            err += dc
            r0 += sr


def cell_of(x, y):
    """The (col, row) of the cell the point (x, y) lies in."""
    # TODO 1: col from x and ORIGIN_X, row from y and ORIGIN_Y, in cells of RESOLUTION
    #         metres (math.floor, not round: a point may lie anywhere in its cell).
    return 0, 0


def inside(col, row):
    return 0 <= col < WIDTH and 0 <= row < HEIGHT


def scan_cells(x, y, yaw, scan):
    """(hits, misses) of one scan: the cells beams end in, and the cells they only cross."""
    hits, crossed = set(), set()
    for i, r in enumerate(scan.ranges):
        if not scan.range_min <= r <= scan.range_max:  # inf and nan fail this test too
            continue
        angle = scan.angle_min + i * scan.angle_increment  # the beam's, seen from the robot
        # TODO 2: the beam's angle in the map (add the robot's heading yaw), the point where
        #         it ends, r metres from (x, y), and that point's cell. With start =
        #         cell_of(x, y), line_cells(*start, *end) gives the cells from the robot to
        #         it: the last one is a hit (add it to hits if it is inside the map), the
        #         others are crossed (those inside the map).
        del angle  # (remove this line once you use it)
    return hits, crossed - hits


def update(log_odds, hits, misses):
    """Add the evidence of one scan: each cell changes once per scan."""
    # TODO 3: add MISS to log_odds[row][col] of every cell in misses, HIT to every cell
    #         in hits, and keep each value between L_MIN and L_MAX.


def occupancy(value):
    """A log-odds as the map publishes it: 100 occupied, 0 free, -1 unknown."""
    # TODO 4: 100 above OCCUPIED_ABOVE, 0 below FREE_BELOW, else -1.
    return -1


def grid_data(log_odds):
    """The map's data: row after row from row 0, each row from column 0."""
    # TODO 5: one list of WIDTH * HEIGHT values, occupancy() of each cell, in that order.
    return []


class LogOddsMapper(Node):
    def __init__(self):
        super().__init__("log_odds_mapper")
        self.log_odds = [[0.0] * WIDTH for _ in range(HEIGHT)]  # 0.0: unknown
        self.pose = None
        # TODO 6: a map user may subscribe long after you published: make this publisher
        #         keep its last map for late subscribers (durability TRANSIENT_LOCAL).
        latched = QoSProfile(depth=1)
        self.publisher = self.create_publisher(OccupancyGrid, "/map", latched)
        self.create_subscription(PoseStamped, "/robot_pose", self.on_pose, 10)
        self.create_subscription(LaserScan, "/scan", self.on_scan, 10)

    def on_pose(self, msg):
        p = msg.pose.position
        self.pose = (p.x, p.y, yaw_of(msg.pose.orientation))

    def on_scan(self, msg):
        if self.pose is None:
            self.get_logger().warn("a scan, but no pose yet: skipped")
            return
        hits, misses = scan_cells(*self.pose, msg)
        update(self.log_odds, hits, misses)
        grid = OccupancyGrid()
        grid.header.frame_id = "map"
        grid.header.stamp = msg.header.stamp
        grid.info.resolution = RESOLUTION
        grid.info.width, grid.info.height = WIDTH, HEIGHT
        grid.info.origin.position.x, grid.info.origin.position.y = ORIGIN_X, ORIGIN_Y
        grid.info.origin.orientation.w = 1.0
        grid.data = grid_data(self.log_odds)
        self.publisher.publish(grid)
        self.get_logger().info(f"{len(hits)} hit cells, {len(misses)} crossed cells")


def main():
    rclpy.init()
    node = LogOddsMapper()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
