"""Exercise: publish a tutorial_interfaces/msg/DetectedObject on /detections."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tutorial_interfaces.msg import DetectedObject


class DetectionPublisher(Node):
    def __init__(self):
        super().__init__("detection_publisher")
        # TODO 1: create a publisher of DetectedObject on the topic "detections".
        # TODO 2: create a timer that calls self.on_timer twice a second.

    def on_timer(self):
        # TODO 3: make a DetectedObject and fill in the header (frame id and stamp),
        #         the label, the pixel values and the nested position_in_camera,
        #         as the table says.
        # TODO 4: publish it.
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
