"""The live session in Foxglove or Lichtblick: the ROS graph over the Foxglove WebSocket protocol.

Learners who will use Foxglove at work open the same topics there that the
dashboard shows. The server is ``foxglove-sdk``'s (from PyPI); this package
feeds it from the ROS graph: every topic as a channel carrying ROS 2 CDR with
its full message definition, a ROS subscription only while a client watches
it, and a client's own publishing (a teleop on ``/cmd_vel``) onto ROS, bounded.
It sits on the ROS layer (``app.ros``) and the bags' message definitions
(``app.bags``) and imports no front end.

- ``limits``  what one client may cost (sizes, rates, counts): plain values and checks
- ``bridge``  ``FoxgloveBridge``: the graph <-> the WebSocket server
- ``serve``   ``ros2-classroom foxglove``: a ROS participant and the bridge until Ctrl+C
"""

from app.foxglove.bridge import FoxgloveBridge
from app.foxglove.limits import BridgeLimits

__all__ = ["BridgeLimits", "FoxgloveBridge"]
