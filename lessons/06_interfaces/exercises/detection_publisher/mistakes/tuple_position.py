"""A plausible mistake: three numbers for a nested Point; publishing it fails."""

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
        msg.header.frame_id = "camera"
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.label = "red_ball"
        msg.pixel_x = 320.0
        msg.pixel_y = 180.0
        msg.radius_px = 24.0
        msg.position_in_camera = (0.15, -0.05, 1.2)
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
