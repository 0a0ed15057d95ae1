"""Accepted, written differently: no class; the message built with keyword arguments."""

import rclpy
from geometry_msgs.msg import Point
from rclpy.executors import ExternalShutdownException
from std_msgs.msg import Header
from tutorial_interfaces.msg import DetectedObject


def main():
    rclpy.init()
    node = rclpy.create_node("detection_publisher")
    out = node.create_publisher(DetectedObject, "/detections", 10)

    def on_circle(c):
        z = 600.0 * 0.03 / c.z
        out.publish(
            DetectedObject(
                header=Header(frame_id="camera", stamp=node.get_clock().now().to_msg()),
                label="red_ball",
                pixel_x=c.x,
                pixel_y=c.y,
                radius_px=c.z,
                position_in_camera=Point(
                    x=(c.x - 320.0) * z / 600.0, y=(c.y - 240.0) * z / 600.0, z=z
                ),
            )
        )

    node.create_subscription(Point, "/circles", on_circle, 10)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
