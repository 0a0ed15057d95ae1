"""A service's request and response as ros2msg text, as the Foxglove bridge advertises them."""

from __future__ import annotations

import pytest

from app.bags.definitions import SEPARATOR, service_definitions
from app.bags.errors import BagError


def test_a_flat_service_is_its_two_halves_without_comments():
    assert service_definitions("std_srvs/srv/SetBool") == (
        "bool data\n",
        "bool success\nstring message\n",
    )


def test_nested_types_follow_each_half_once_as_a_bag_stores_them():
    request, response = service_definitions("nav_msgs/srv/GetPlan")
    assert request.startswith("geometry_msgs/PoseStamped start\ngeometry_msgs/PoseStamped goal\n")
    headers = [line for line in request.splitlines() if line.startswith("MSG: ")]
    assert "MSG: geometry_msgs/PoseStamped" in headers and len(headers) == len(set(headers))
    assert f"{SEPARATOR}\nMSG: std_msgs/Header\n" in request
    assert response.startswith("nav_msgs/Path plan\n") and "MSG: nav_msgs/Path" in response


@pytest.mark.parametrize(
    ("srvtype", "words"),
    [
        ("std_msgs/msg/String", "not a service type"),
        ("std_srvs/srv/NoSuchThing", "no definition of std_srvs/srv/NoSuchThing"),
    ],
)
def test_what_is_not_an_installed_service_is_refused(srvtype, words):
    with pytest.raises(BagError, match=words):
        service_definitions(srvtype)
