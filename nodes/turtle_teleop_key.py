"""turtle_teleop_key: drive turtle1 with the keyboard, in a terminal or from the browser.

The node ``/teleop_turtle`` does what ROS 2's ``turtle_teleop_key`` does:

- arrow keys publish one ``geometry_msgs/msg/Twist`` on ``turtle1/cmd_vel``
  each (up/down: ``linear.x`` = +/- ``scale_linear``; left/right:
  ``angular.z`` = +/- ``scale_angular``; both parameters default to 2.0);
  turtlesim stops the turtle 1 s after the last one, so holding a key drives;
- G B V C D E R T send a ``turtle1/rotate_absolute`` goal to the heading
  0, -45, -90, -135, 180, 135, 90, 45 degrees; F cancels the last goal,
  even one whose answer has not come back yet (upstream's F then cancels
  the goal before it, already done, and the turtle turns on: a key pressed
  quickly, or an answer slowed by a busy machine, is not lost here);
- Q quits (in a terminal).

Two sources of keys, so it works with and without a terminal:

- **A terminal** (stdin is a TTY, as with ``ros2-classroom`` on a shell): keys
  are read raw, one byte at a time, like upstream.
- **The browser**: the dashboard starts this node without a terminal and
  sends key names (``up``, ``down``, ``left``, ``right``, or a letter) as
  ``std_msgs/msg/String`` on ``~/_key`` (``/teleop_turtle/_key``). A name
  with a token starting with ``_`` is *hidden* in ROS: ``ros2 topic list``
  leaves it out unless asked, so the tutorial's topic list is unchanged.
  The keys of both sources go through the same ``handle_key``.

ROS concepts shown: a publisher with explicit QoS (reliable, keep-last 7, as
turtlesim), an ``ActionClient`` with ``send_goal_async`` and
``cancel_goal_async``, parameters read at every key, remapping
(``--ros-args -r turtle1/cmd_vel:=turtle2/cmd_vel`` drives another turtle).
"""

from __future__ import annotations

import os
import sys
import threading

import rclpy
from geometry_msgs.msg import Twist
from rclpy.action import ActionClient
from rclpy.action.client import ClientGoalHandle
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.task import Future
from std_msgs.msg import String
from turtlesim.action import RotateAbsolute

from nodes.common.run import init_ros, ros_started, stopped_quietly
from nodes.turtlesim_node import TOPIC_QOS, declare_rclcpp_parameters

MOVES = {"up": (1.0, 0.0), "down": (-1.0, 0.0), "left": (0.0, 1.0), "right": (0.0, -1.0)}
HEADINGS = {  # radians, upstream's rounded values
    "g": 0.0, "t": 0.7854, "r": 1.5708, "e": 2.3562,
    "d": 3.1416, "c": -2.3562, "v": -1.5708, "b": -0.7854,
}  # fmt: skip
# Upstream reads single bytes: an arrow key's escape sequence ends in A, B, C or D.
TERMINAL_KEYS = {"A": "up", "B": "down", "C": "right", "D": "left"}
BANNER = (
    "Reading from keyboard\n"
    "---------------------------\n"
    "Use arrow keys to move the turtle.\n"
    "Use G|B|V|C|D|E|R|T keys to rotate to absolute orientations. 'F' to cancel a rotation.\n"
    "'Q' to quit."
)


class TeleopTurtle(Node):
    def __init__(self) -> None:
        super().__init__("teleop_turtle")
        self.declare_parameter("scale_angular", 2.0)
        self.declare_parameter("scale_linear", 2.0)
        declare_rclcpp_parameters(self)
        self.twist_publisher = self.create_publisher(Twist, "turtle1/cmd_vel", TOPIC_QOS)
        self.rotate_client = ActionClient(self, RotateAbsolute, "turtle1/rotate_absolute")
        self.goal_handle: ClientGoalHandle | None = None
        # The last goal sent, until its answer comes; F meanwhile cancels it on arrival.
        # Keys and answers are handled on the executor's one thread: no lock.
        self.sent: Future | None = None
        self.cancel_on_answer = False
        self.key_subscription = self.create_subscription(String, "~/_key", self.on_key, 10)
        self.quit = threading.Event()

    def on_key(self, msg: String) -> None:
        self.handle_key(msg.data)

    def handle_key(self, key: str) -> None:
        """One key press, by name: 'up', 'down', 'left', 'right' or a letter."""
        key = key.strip()
        key = key if len(key) > 1 else key.lower()
        if key in MOVES:
            linear, angular = MOVES[key]
            twist = Twist()
            twist.linear.x = self.get_parameter("scale_linear").value * linear
            twist.angular.z = self.get_parameter("scale_angular").value * angular
            self.twist_publisher.publish(twist)
        elif key in HEADINGS:
            self.send_goal(HEADINGS[key])
        elif key == "f":
            self.cancel_goal()
        elif key == "q":
            self.quit.set()
        # Any other key is ignored, as upstream does.

    def send_goal(self, theta: float) -> None:
        future = self.rotate_client.send_goal_async(RotateAbsolute.Goal(theta=theta))
        self.sent, self.cancel_on_answer = future, False
        future.add_done_callback(self.on_goal_response)

    def on_goal_response(self, future: Future) -> None:
        if future is not self.sent:
            return  # a later goal was sent meanwhile: F is for that one
        self.sent = None
        self.goal_handle = future.result()
        if self.cancel_on_answer and self.goal_handle is not None:
            self.cancel_on_answer = False
            self.goal_handle.cancel_goal_async()

    def cancel_goal(self) -> None:
        if self.sent is not None:  # the goal is on its way: cancel it once it is answered
            self.cancel_on_answer = True
        elif self.goal_handle is not None:
            self.goal_handle.cancel_goal_async()


def read_terminal_keys(node: TeleopTurtle, executor: SingleThreadedExecutor) -> None:
    """Raw keys from the terminal until Q, Ctrl+C or shutdown (upstream's key loop)."""
    import termios

    fd = sys.stdin.fileno()
    cooked = termios.tcgetattr(fd)
    raw = termios.tcgetattr(fd)
    raw[3] &= ~(termios.ICANON | termios.ECHO)
    raw[6][termios.VMIN] = 0
    raw[6][termios.VTIME] = 1  # read() returns after 0.1 s without a key: check for quit
    termios.tcsetattr(fd, termios.TCSANOW, raw)
    try:
        while rclpy.ok() and not node.quit.is_set():
            byte = os.read(fd, 1).decode("latin-1")
            if byte:
                # Handled in the spinning thread: rclpy's ActionClient drops a goal's
                # answer if it arrives while another thread is still sending the goal.
                executor.create_task(node.handle_key, TERMINAL_KEYS.get(byte, byte))
    finally:
        termios.tcsetattr(fd, termios.TCSANOW, cooked)


def main(args=None) -> None:
    node: TeleopTurtle | None = None
    executor: SingleThreadedExecutor | None = None
    spinner: threading.Thread | None = None
    try:
        with stopped_quietly():  # Ctrl+C or SIGTERM, even during start-up: leave quietly
            init_ros(args)
            node = TeleopTurtle()
            executor = SingleThreadedExecutor()
            executor.add_node(node)
            ros_started(executor)
            print(BANNER, flush=True)
            if sys.stdin.isatty():
                spinner = threading.Thread(target=executor.spin, daemon=True)
                spinner.start()
                read_terminal_keys(node, executor)
            else:
                print(f"(no terminal: reading key names from {node.key_subscription.topic_name})")
                while rclpy.ok() and not node.quit.is_set():
                    executor.spin_once(timeout_sec=0.1)
    finally:
        if executor is not None:
            executor.shutdown()
        if spinner is not None:
            spinner.join(2.0)  # destroying the node under a spinning thread aborts rclpy
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
