"""The ROS layer: everything the dashboard knows about ROS 2, each piece in one home.

Every front end (the ros2-like verbs in ``app.ros2cli``, the panels and 3D
scene in ``app.panels`` and ``app.scene``, the lessons in ``app.lessons``)
does its ROS work through these modules and never through each other
(import-linter contracts in pyproject.toml keep it so):

- ``runtime``   the dashboard's participant: one context, one node, one executor thread
- ``graph``     what is on the graph as plain data, and the live/ghost rule
- ``names``     node-name helpers and the names the graph hides
- ``monitor``   one raw subscription for echo, hz, bw and checks
- ``rates``     rates of a changing set of topics; ``rosout``: the /rosout log
- ``calls``     service calls, action goals, non-blocking service polling
- ``params``    parameter get/set/describe and value conversion
- ``lifecycle`` managed-node state and transitions
- ``qos``       matching a publisher's QoS; printing a profile
- ``convert``   any message, service or action type <-> dicts and YAML
- ``context``   limits and cancellation for blocking calls; ``errors``: what they raise

Blocking calls take a ``CallContext`` and run on worker threads; subscription
callbacks run on the runtime's executor thread and only record.
"""
