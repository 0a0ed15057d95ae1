"""fibonacci_action_server: compute Fibonacci sequences as a ROS 2 action.

An action is a long-running request: the client sends a *goal*, the server
accepts or rejects it, sends *feedback* while it works, and finally a
*result*. The client may ask to *cancel* the goal at any time. This server
offers ``/fibonacci`` (``tutorial_interfaces/action/Fibonacci``): goal
``order``, feedback ``partial_sequence``, result ``sequence``. Order N gives
the N+1 numbers F(0)..F(N), starting 0, 1; order 5 gives 0 1 1 2 3 5.

Rules this server follows (each one is a design decision an action server
must make):

- **Range.** Goals with ``order`` outside 0..46 are rejected, and the reason is
  logged: F(47) no longer fits in the ``int32`` the sequence is made of.
- **Pace.** One new number per ``step_period`` seconds (a parameter, default
  0.5 s), with feedback after each number, so a learner can watch it.
- **Cancel.** Cancel requests are always accepted; the goal stops before its
  next step and ends as CANCELED, carrying the numbers computed so far.
- **Concurrent goals: the newest goal wins.** A new goal is always accepted
  (if in range); a goal still running is then aborted (ABORTED, with its
  partial sequence as result), as a robot would drop its old destination
  when given a new one. Only one goal ever executes at a time.

ROS concepts shown
- ``ActionServer(node, type, name, execute_callback, goal_callback=...,
  cancel_callback=..., handle_accepted_callback=...)`` and the goal states
  (accepted, executing, canceling, succeeded, canceled, aborted);
- ``goal_handle.publish_feedback``, ``succeed``, ``abort``, ``canceled``;
- a ``MultiThreadedExecutor`` with a ``ReentrantCallbackGroup``: while one
  goal executes (and sleeps between steps), other threads still answer new
  goals and cancel requests;
- a parameter with a descriptor (``step_period``) read at every step.
"""

import threading

from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.action.server import ServerGoalHandle
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from tutorial_interfaces.action import Fibonacci

from nodes.common.run import spin_node

MIN_ORDER, MAX_ORDER = 0, 46  # F(46) = 1836311903 is the last that fits in int32


class FibonacciActionServer(Node):
    def __init__(self) -> None:
        super().__init__("fibonacci_action_server")
        self.declare_parameter(
            "step_period",
            0.5,
            ParameterDescriptor(
                description="seconds between two numbers (and two feedback messages)",
                floating_point_range=[FloatingPointRange(from_value=0.0, to_value=5.0)],
            ),
        )
        self.goal_lock = threading.Lock()  # guards current_goal and goal state changes
        self.current_goal: ServerGoalHandle | None = None
        self.shutting_down = threading.Event()  # set by stop_goals() on Ctrl+C or SIGTERM
        self.context.on_shutdown(self.stop_goals)  # wakes a sleeping goal as ROS shuts down
        self.action_server = ActionServer(
            self,
            Fibonacci,
            "fibonacci",
            execute_callback=self.execute_goal,
            goal_callback=self.on_goal_request,
            handle_accepted_callback=self.on_goal_accepted,
            cancel_callback=self.on_cancel_request,
            callback_group=ReentrantCallbackGroup(),
        )
        self.get_logger().info(
            f"Ready: send goals to /fibonacci with order {MIN_ORDER}..{MAX_ORDER}"
        )

    def on_goal_request(self, goal: Fibonacci.Goal) -> GoalResponse:
        if not MIN_ORDER <= goal.order <= MAX_ORDER:
            self.get_logger().warn(
                f"Rejecting goal: order {goal.order} is outside {MIN_ORDER}..{MAX_ORDER} "
                f"(F({MAX_ORDER + 1}) would overflow int32)"
            )
            return GoalResponse.REJECT
        self.get_logger().info(f"Accepting goal with order {goal.order}")
        return GoalResponse.ACCEPT

    def on_goal_accepted(self, goal_handle: ServerGoalHandle) -> None:
        with self.goal_lock:
            previous = self.current_goal
            if previous is not None and previous.is_active:
                self.get_logger().info("A new goal arrived: aborting the goal still running")
                previous.abort()
            self.current_goal = goal_handle
            # Still under the lock: no other goal can see this one as current while it is
            # only accepted (aborting an accepted goal is an invalid transition that raises).
            goal_handle.execute()

    def on_cancel_request(self, goal_handle: ServerGoalHandle) -> CancelResponse:
        self.get_logger().info("Cancel requested: the goal will stop before its next step")
        return CancelResponse.ACCEPT

    def execute_goal(self, goal_handle: ServerGoalHandle) -> Fibonacci.Result:
        sequence: list[int] = []
        try:
            return self.compute(goal_handle, sequence)
        except Exception:
            if self.context.ok():
                raise
            # Ctrl+C or SIGTERM shut ROS down in the middle of a step (while publishing
            # feedback, say): the node is ending, so the goal ends quietly with it.
            return self.abandon_goal(goal_handle, sequence)

    def compute(self, goal_handle: ServerGoalHandle, sequence: list[int]) -> Fibonacci.Result:
        """Grow ``sequence`` one number per step, with feedback, to the goal's order."""
        order = goal_handle.request.order
        sequence += [0, 1][: order + 1]
        self.get_logger().info(f"Executing goal: order {order}")
        self.send_feedback(goal_handle, sequence)
        while len(sequence) < order + 1:
            # Like time.sleep(step_period), but wakes at once when the node shuts down.
            if self.shutting_down.wait(self.get_parameter("step_period").value):
                return self.abandon_goal(goal_handle, sequence)
            with self.goal_lock:
                if not goal_handle.is_active:
                    self.get_logger().info(f"Goal aborted by a newer goal after {sequence}")
                    return Fibonacci.Result(sequence=sequence)
                if goal_handle.is_cancel_requested:
                    goal_handle.canceled()
                    self.get_logger().info(f"Goal canceled after {sequence}")
                    return Fibonacci.Result(sequence=sequence)
                sequence.append(sequence[-1] + sequence[-2])
            self.send_feedback(goal_handle, sequence)
        with self.goal_lock:
            if not goal_handle.is_active:
                return Fibonacci.Result(sequence=sequence)
            goal_handle.succeed()
        self.get_logger().info(f"Goal succeeded: {sequence}")
        return Fibonacci.Result(sequence=sequence)

    def abandon_goal(self, goal_handle: ServerGoalHandle, sequence: list[int]) -> Fibonacci.Result:
        """The node is shutting down: end the goal as ABORTED if ROS still lets us."""
        with self.goal_lock:
            if goal_handle.is_active:
                try:
                    goal_handle.abort()
                except Exception:  # after SIGTERM the context is gone: nothing can be sent
                    pass
        return Fibonacci.Result(sequence=sequence)

    def stop_goals(self) -> None:
        """The node is stopping: a goal sleeping between two steps wakes up and ends."""
        self.shutting_down.set()

    def send_feedback(self, goal_handle: ServerGoalHandle, sequence: list[int]) -> None:
        goal_handle.publish_feedback(Fibonacci.Feedback(partial_sequence=sequence))
        self.get_logger().info(f"Feedback: {sequence}")


def main(args=None) -> None:
    # Several threads: while one goal sleeps between steps, another answers new goals
    # and cancel requests. On Ctrl+C a goal still executing is woken to stop at once.
    spin_node(
        FibonacciActionServer,
        args,
        executor=MultiThreadedExecutor,
        before_shutdown=FibonacciActionServer.stop_goals,
    )


if __name__ == "__main__":
    main()
