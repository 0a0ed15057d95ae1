"""Which turtles the turtlesim stage and panel list: those whose pose a node publishes."""

from __future__ import annotations

from app.panels.turtlesim_panel import POSE_TYPE, pose_topics
from app.ros.graph import GraphSnapshot, TopicInfo


def test_a_turtle_is_listed_while_its_pose_is_published_not_while_only_we_listen():
    graph = GraphSnapshot(
        topics=(
            TopicInfo("/turtle1/pose", (POSE_TYPE,), 1, 1),
            # turtle2 was killed (or its sim restarted): only our subscription is left.
            TopicInfo("/turtle2/pose", (POSE_TYPE,), 0, 1, own_subscribers=1),
            TopicInfo("/turtle1/cmd_vel", ("geometry_msgs/msg/Twist",), 1, 1),
        )
    )
    assert pose_topics(graph, "/turtlesim") == {"turtle1": "/turtle1/pose"}


def test_turtles_of_a_namespaced_sim_only():
    graph = GraphSnapshot(
        topics=(
            TopicInfo("/turtlesim1/turtle1/pose", (POSE_TYPE,), 1, 0),
            TopicInfo("/turtlesim2/turtle1/pose", (POSE_TYPE,), 1, 0),
        )
    )
    assert pose_topics(graph, "/turtlesim1/turtlesim") == {"turtle1": "/turtlesim1/turtle1/pose"}
