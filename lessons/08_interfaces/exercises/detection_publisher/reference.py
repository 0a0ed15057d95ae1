"""Reference solution: every circle found in the image becomes a DetectedObject on /detections."""

import rclpy
from geometry_msgs.msg import Point
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tutorial_interfaces.msg import DetectedObject

FOCAL_PX = 600.0  # the camera's focal length, in pixels
CENTRE_U, CENTRE_V = 320.0, 240.0  # the image centre (a 640x480 camera)
BALL_RADIUS_M = 0.03  # the ball is 6 cm across


class DetectionPublisher(Node):
    def __init__(self):
        super().__init__("detection_publisher")
        self.publisher = self.create_publisher(DetectedObject, "detections", 10)
        self.subscription = self.create_subscription(Point, "circles", self.on_circle, 10)

    def on_circle(self, circle):
        msg = DetectedObject()
        msg.header.frame_id = "camera"
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.label = "red_ball"
        msg.pixel_x = circle.x
        msg.pixel_y = circle.y
        msg.radius_px = circle.z
        # A nested message is already there: fill in its fields.
        depth = FOCAL_PX * BALL_RADIUS_M / circle.z
        msg.position_in_camera.x = (circle.x - CENTRE_U) * depth / FOCAL_PX
        msg.position_in_camera.y = (circle.y - CENTRE_V) * depth / FOCAL_PX
        msg.position_in_camera.z = depth
        self.publisher.publish(msg)


def main():
    rclpy.init()
    node = DetectionPublisher()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
