"""Exercise: every circle found in the image becomes a DetectedObject on /detections."""

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
        # TODO 1: create a publisher of DetectedObject on the topic "detections".
        self.subscription = self.create_subscription(Point, "circles", self.on_circle, 10)

    def on_circle(self, circle):
        # circle.x, circle.y: the circle's centre (column, row); circle.z: its radius (pixels).
        # TODO 2: make a DetectedObject and fill in the header (frame id and stamp),
        #         the label, the pixel values and the nested position_in_camera,
        #         as the statement says.
        # TODO 3: publish it.
        pass


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
