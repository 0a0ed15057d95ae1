"""A plausible mistake: the header is left empty, so nobody knows the frame."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tutorial_interfaces.msg import DetectedObject


class DetectionPublisher(Node):
    def __init__(self):
        super().__init__("detection_publisher")
        self.publisher = self.create_publisher(DetectedObject, "detections", 10)
        self.timer = self.create_timer(0.5, self.on_timer)

    def on_timer(self):
        msg = DetectedObject()
        msg.label = "red_ball"
        msg.pixel_x = 320.0
        msg.pixel_y = 180.0
        msg.radius_px = 24.0
        # A nested message is already there: fill in its fields.
        msg.position_in_camera.x = 0.15
        msg.position_in_camera.y = -0.05
        msg.position_in_camera.z = 1.2
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
