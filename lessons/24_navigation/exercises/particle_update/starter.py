"""Exercise: the particle filter's motion update, from /particles and /odom to /particles_moved."""

import math
import random

import rclpy
from geometry_msgs.msg import Pose, PoseArray
from nav_msgs.msg import Odometry
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

# How noisy the wheels are: rotation from rotation, rotation from translation,
# translation from translation, translation from rotation.
ALPHA1, ALPHA2, ALPHA3, ALPHA4 = 0.05, 0.01, 0.02, 0.01


def yaw_of(q):
    """The heading (rad) of a quaternion that turns about z only."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def normalize(angle):
    """The same angle between -pi and pi."""
    return math.atan2(math.sin(angle), math.cos(angle))


def motion_between(before, after):
    """(rot1, trans, rot2): the odometry's step from pose (x, y, yaw) before to after."""
    # TODO 1: rot1 turns from the old heading to the direction of travel (atan2 of the
    #         step in y and x), trans is the length of the step, rot2 turns from there
    #         to the new heading. normalize() both turns.
    return 0.0, 0.0, 0.0


def move(particle, rot1, trans, rot2):
    """One particle (x, y, yaw) moved by the step, each part with noise of its own."""
    x, y, yaw = particle
    # TODO 2: add noise to each part (rot1, trans, rot2) with random.gauss(0.0, sigma),
    #         where sigma is the square root of the variance the statement gives for it.
    # TODO 3: turn the particle's own heading by the noisy rot1, move the noisy trans
    #         along it, then turn by the noisy rot2.
    return x, y, yaw


class ParticleUpdate(Node):
    def __init__(self):
        super().__init__("particle_update")
        self.particles = []  # (x, y, yaw) in the map frame
        self.frame_id = "map"
        self.last_odom = None
        self.publisher = self.create_publisher(PoseArray, "/particles_moved", 10)
        self.create_subscription(PoseArray, "/particles", self.on_particles, 10)
        self.create_subscription(Odometry, "/odom", self.on_odom, 10)

    def on_particles(self, msg):
        self.frame_id = msg.header.frame_id
        self.particles = [(p.position.x, p.position.y, yaw_of(p.orientation)) for p in msg.poses]

    def on_odom(self, msg):
        p = msg.pose.pose
        odom = (p.position.x, p.position.y, yaw_of(p.orientation))
        if self.last_odom is not None and self.particles:
            rot1, trans, rot2 = motion_between(self.last_odom, odom)
            self.particles = [move(q, rot1, trans, rot2) for q in self.particles]
            out = PoseArray()
            out.header.stamp = msg.header.stamp
            out.header.frame_id = self.frame_id
            for x, y, yaw in self.particles:
                pose = Pose()
                pose.position.x, pose.position.y = x, y
                pose.orientation.z, pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
                out.poses.append(pose)
            self.publisher.publish(out)
            self.get_logger().info(
                f"moved {len(self.particles)} particles by rot1 {rot1:.2f}, "
                f"trans {trans:.2f}, rot2 {rot2:.2f}"
            )
        self.last_odom = odom


def main():
    rclpy.init()
    node = ParticleUpdate()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
