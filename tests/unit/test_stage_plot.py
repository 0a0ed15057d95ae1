"""The plot stage's choices: which topics it draws, and a minute of samples per chart."""

from __future__ import annotations

from app.ros.graph import GraphSnapshot, TopicInfo
from app.stage.plot_stage import MAX_SERIES, WINDOW_SEC, History, plotted_topics


def _topic(
    name: str, kind: str, publishers: int = 1, own: int = 0, subscribers: int = 0
) -> TopicInfo:
    return TopicInfo(name, (kind,), publishers, subscribers, own_publishers=own)


def test_it_plots_what_is_published_without_plumbing_images_or_the_teachers_reports():
    graph = GraphSnapshot(
        topics=(
            _topic("/chatter", "std_msgs/msg/String", 1, own=1, subscribers=1),  # a bag played
            _topic("/turtle1/cmd_vel", "geometry_msgs/msg/Twist", 1, own=1),  # nobody listens
            _topic("/executor_demo/fast_rate", "std_msgs/msg/Float64"),
            _topic("/rosout", "rcl_interfaces/msg/Log", 3),
            _topic("/parameter_events", "rcl_interfaces/msg/ParameterEvent", 3),
            _topic("/camera/image_raw", "sensor_msgs/msg/Image"),
            _topic("/classroom/progress", "classroom_interfaces/msg/LearnerProgress", 1, own=1),
            _topic("/sim_teleop_key/_key", "std_msgs/msg/String", 1, own=1),  # hidden
            _topic("/nobody", "std_msgs/msg/String", 0),
        )
    )
    assert plotted_topics(graph) == {
        "/chatter": "std_msgs/msg/String",
        "/executor_demo/fast_rate": "std_msgs/msg/Float64",
    }


def test_at_most_max_series_lines():
    graph = GraphSnapshot(
        topics=tuple(_topic(f"/t{i:02d}", "std_msgs/msg/Int32") for i in range(20))
    )
    assert list(plotted_topics(graph)) == [f"/t{i:02d}" for i in range(MAX_SERIES)]


def test_history_keeps_a_minute_and_starts_over_when_the_topics_change():
    history = History()
    for second in range(100):
        history.add(float(second), {"/a": 1.0, "/b": float(second)})
    t, a, b = history.data()
    assert t[0] == -WINDOW_SEC and t[-1] == 0.0  # seconds before the newest sample
    assert list(a) == [1.0] * len(t) and b[-1] == 99.0
    history.add(100.0, {"/a": 2.0})  # /b left
    assert history.names == ("/a",)
    t, a = history.data()
    assert list(t) == [0.0] and list(a) == [2.0]
