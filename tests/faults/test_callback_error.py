"""A callback of ours that raises must not end the dashboard's observer node.

Every panel, check and 3D view reads from that one node's executor thread: a
single bad message for a single callback once stopped all of them (seen on a
lesson walk of the navigation unit). The executor now says where it raised,
once, and spins on.
"""

from __future__ import annotations

import pytest
from std_msgs.msg import String

from tests.conftest import wait_until

pytestmark = [pytest.mark.ros, pytest.mark.timeout(60)]


def test_a_callback_that_raises_is_reported_once_and_the_node_spins_on(probe, capfd):
    node = probe.node
    good: list[str] = []

    def faulty(msg: String) -> None:
        raise ValueError(f"cannot read {msg.data!r}")

    node.create_subscription(String, "/callback_error/bad", faulty, 10)
    node.create_subscription(String, "/callback_error/good", lambda m: good.append(m.data), 10)
    bad_pub = node.create_publisher(String, "/callback_error/bad", 10)
    good_pub = node.create_publisher(String, "/callback_error/good", 10)

    wait_until(lambda: bad_pub.get_subscription_count() == 1, what="the faulty subscription")
    for i in range(3):
        bad_pub.publish(String(data=f"bad {i}"))
    wait_until(lambda: probe.callback_errors == 3, what="three raised callbacks")

    good_pub.publish(String(data="still here"))
    wait_until(lambda: good == ["still here"], what="a message after the errors")

    err = capfd.readouterr().err
    assert err.count("a callback of /test_probe raised (spinning on)") == 1, err
    assert "ValueError: cannot read 'bad 0'" in err
