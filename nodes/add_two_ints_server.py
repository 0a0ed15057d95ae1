"""add_two_ints_server: answer requests on the /add_two_ints service.

A service is a remote procedure call: a client sends one request and waits
for exactly one response. This server offers ``/add_two_ints`` of type
``tutorial_interfaces/srv/AddTwoInts`` (request ``int64 a, int64 b``; response
``int64 sum``) and logs every request it answers.

ROS concepts shown
- ``create_service(type, name, callback)``: ROS calls the callback with the
  request and an empty response object; the callback fills in the response
  and returns it;
- the service type is generated from a ``.srv`` file: the part above ``---``
  is the request, the part below is the response;
- a server is idle until a request arrives; it does not poll;
- service introspection (new in Jazzy): ``configure_introspection`` makes the
  server announce each request and response on the hidden topic
  ``/add_two_ints/_service_event`` (here only that they happened, not their
  contents), so tools can show calls as they happen.

Try it: ``ros2 run tutorial_nodes add_two_ints_server``, then
``ros2 run tutorial_nodes add_two_ints_client`` (adds 2 and 3), or from a full ROS
install ``ros2 service call /add_two_ints tutorial_interfaces/srv/AddTwoInts
"{a: 2, b: 3}"``.
"""

from rclpy.node import Node
from rclpy.qos import qos_profile_system_default
from rclpy.service_introspection import ServiceIntrospectionState
from tutorial_interfaces.srv import AddTwoInts

from nodes.common.run import spin_node

INT64_MIN, INT64_MAX = -(2**63), 2**63 - 1


class AddTwoIntsServer(Node):
    def __init__(self) -> None:
        super().__init__("add_two_ints_server")
        self.service = self.create_service(AddTwoInts, "add_two_ints", self.on_add_two_ints)
        self.service.configure_introspection(
            self.get_clock(), qos_profile_system_default, ServiceIntrospectionState.METADATA
        )
        self.get_logger().info("Ready: call /add_two_ints with two integers a and b")

    def on_add_two_ints(
        self, request: AddTwoInts.Request, response: AddTwoInts.Response
    ) -> AddTwoInts.Response:
        total = request.a + request.b
        if not INT64_MIN <= total <= INT64_MAX:
            # int64 arithmetic in C would wrap around silently; say so instead.
            self.get_logger().warn(f"{request.a} + {request.b} overflows int64; answering 0")
            total = 0
        response.sum = total
        self.get_logger().info(f"Incoming request: a={request.a} b={request.b} -> sum={total}")
        return response


def main(args=None) -> None:
    spin_node(AddTwoIntsServer, args)


if __name__ == "__main__":
    main()
