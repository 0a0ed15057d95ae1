"""The default DDS profile keeps every locator on loopback."""

import xml.etree.ElementTree as ET

from app.dds import LOOPBACK_PROFILE, NETWORK_OPT_IN_VAR, PROFILE_VAR, configure_dds_env

NS = {"f": "http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"}


def test_profile_uses_only_loopback_addresses():
    root = ET.parse(LOOPBACK_PROFILE).getroot()
    addresses = [el.text for el in root.iter(f"{{{NS['f']}}}address")]
    assert addresses, "the profile must name its addresses explicitly"
    assert set(addresses) == {"127.0.0.1"}
    assert root.find(".//f:useBuiltinTransports", NS).text == "false"
    participant = root.find(".//f:participant", NS)
    assert participant.get("is_default_profile") == "true"
    assert root.find(".//f:metatrafficMulticastLocatorList", NS) is None


def test_env_defaults_to_loopback_and_drops_localhost_range():
    env = {"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    configure_dds_env(env, domain_id=7)
    assert env[PROFILE_VAR] == str(LOOPBACK_PROFILE)
    assert env["ROS_DOMAIN_ID"] == "7"
    assert "ROS_AUTOMATIC_DISCOVERY_RANGE" not in env


def test_network_is_an_explicit_opt_in_that_children_inherit():
    env = configure_dds_env({}, network=True)
    assert PROFILE_VAR not in env and env[NETWORK_OPT_IN_VAR] == "1"
    configure_dds_env(env)  # a child started by a network-mode dashboard
    assert PROFILE_VAR not in env


def test_bad_domain_id_is_refused():
    import pytest

    with pytest.raises(ValueError, match="between 0 and"):
        configure_dds_env({}, domain_id=500)
