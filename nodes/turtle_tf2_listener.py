"""turtle_tf2_listener: the "Writing a listener (Python)" tutorial's node.

It spawns ``turtle2`` through ``/spawn``, then once a second looks up where
``target_frame`` (parameter, default ``turtle1``) is as seen from turtle2 and
drives turtle2 towards it on ``/turtle2/cmd_vel``: turn by the bearing, go
forward by half the distance. With the broadcasters running, turtle2 follows
turtle1.

ROS concepts shown: Buffer + TransformListener, ``lookup_transform`` with time
zero (the latest common time), TransformException when a frame is missing.
"""

import math

from geometry_msgs.msg import TransformStamped, Twist
from rclpy.node import Node
from rclpy.task import Future
from rclpy.time import Time
from tf2_ros import TransformException
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener
from turtlesim.srv import Spawn

from nodes.common.run import spin_node


class FrameListener(Node):
    def __init__(self) -> None:
        super().__init__("turtle_tf2_frame_listener")
        # Declare and acquire `target_frame` parameter
        self.target_frame = (
            self.declare_parameter("target_frame", "turtle1").get_parameter_value().string_value
        )
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        # Create a client to spawn a turtle
        self.spawner = self.create_client(Spawn, "spawn")
        # Boolean values to store the information
        # if the service for spawning turtle is available
        self.turtle_spawning_service_ready = False
        # if the turtle was successfully spawned
        self.turtle_spawned = False
        self.result: Future  # the spawn call, once it is made
        # Create turtle2 velocity publisher
        self.publisher = self.create_publisher(Twist, "turtle2/cmd_vel", 1)
        # Call on_timer function every second
        self.timer = self.create_timer(1.0, self.on_timer)

    def lookup(self, to_frame_rel: str, from_frame_rel: str) -> TransformStamped:
        """The latest transform (time zero); the "Using time" tutorials change only this call."""
        return self.tf_buffer.lookup_transform(to_frame_rel, from_frame_rel, Time())

    def on_timer(self) -> None:
        # Store frame names in variables that will be used to
        # compute transformations
        from_frame_rel = self.target_frame
        to_frame_rel = "turtle2"
        if self.turtle_spawning_service_ready:
            if self.turtle_spawned:
                # Look up for the transformation between target_frame and turtle2 frames
                # and send velocity commands for turtle2 to reach target_frame
                try:
                    t = self.lookup(to_frame_rel, from_frame_rel)
                except TransformException as ex:
                    self.get_logger().info(
                        f"Could not transform {to_frame_rel} to {from_frame_rel}: {ex}"
                    )
                    return
                msg = Twist()
                scale_rotation_rate = 1.0
                msg.angular.z = scale_rotation_rate * math.atan2(
                    t.transform.translation.y, t.transform.translation.x
                )
                scale_forward_speed = 0.5
                msg.linear.x = scale_forward_speed * math.sqrt(
                    t.transform.translation.x**2 + t.transform.translation.y**2
                )
                self.publisher.publish(msg)
            else:
                if self.result.done():
                    self.get_logger().info(f"Successfully spawned {self.result.result().name}")
                    self.turtle_spawned = True
                else:
                    self.get_logger().info("Spawn is not finished")
        else:
            if self.spawner.service_is_ready():
                # Initialize request with turtle name and coordinates
                # Note that x, y and theta are defined as floats in turtlesim/srv/Spawn
                request = Spawn.Request()
                request.name = "turtle2"
                request.x = float(4)
                request.y = float(2)
                request.theta = float(0)
                # Call request
                self.result = self.spawner.call_async(request)
                self.turtle_spawning_service_ready = True
            else:
                # Check if the service is ready
                self.get_logger().info("Service is not ready")


def main(args=None) -> None:
    spin_node(FrameListener, args)


if __name__ == "__main__":
    main()
