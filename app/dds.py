"""Which DDS network a process joins: loopback only unless the user opts in.

Fast DDS multicasts discovery on every network card by default. Every
process this project starts (the dashboard, each node, the CLI, the tests)
gets the loopback-only profile in ``dds_loopback.xml`` unless the user asks
for the network explicitly (``--network``).
"""

from __future__ import annotations

import os
from collections.abc import MutableMapping
from pathlib import Path

LOOPBACK_PROFILE = Path(__file__).resolve().parent / "dds_loopback.xml"

# Fast DDS 2.14 (Jazzy) reads only this spelling; FASTDDS_DEFAULT_PROFILES_FILE
# is silently ignored there.
PROFILE_VAR = "FASTRTPS_DEFAULT_PROFILES_FILE"
# Set to "1" to let DDS use the real network cards (talk to a robot or a class).
NETWORK_OPT_IN_VAR = "CLASSROOM_DDS_NETWORK"

MAX_DOMAIN_ID = 101  # highest id whose default ports do not collide (Fast DDS)


def validate_domain_id(domain_id: int) -> int:
    if not 0 <= domain_id <= MAX_DOMAIN_ID:
        raise ValueError(f"ROS domain id must be between 0 and {MAX_DOMAIN_ID}, got {domain_id}")
    return domain_id


def configure_dds_env(
    env: MutableMapping[str, str],
    *,
    domain_id: int | None = None,
    network: bool | None = None,
) -> MutableMapping[str, str]:
    """Make ``env`` select our DDS setup; returns it for chaining.

    ``network=None`` keeps whatever choice ``env`` already carries (a node
    started by the dashboard inherits the dashboard's choice).
    """
    if network is None:
        network = env.get(NETWORK_OPT_IN_VAR) == "1"
    env["RMW_IMPLEMENTATION"] = "rmw_fastrtps_cpp"
    if network:
        env[NETWORK_OPT_IN_VAR] = "1"
        if env.get(PROFILE_VAR) == str(LOOPBACK_PROFILE):
            del env[PROFILE_VAR]
    else:
        env[NETWORK_OPT_IN_VAR] = "0"
        env[PROFILE_VAR] = str(LOOPBACK_PROFILE)
        # LOCALHOST discovery brings the card's address back next to our
        # profile's locators; the profile alone keeps traffic on loopback.
        env.pop("ROS_AUTOMATIC_DISCOVERY_RANGE", None)
        env.pop("ROS_STATIC_PEERS", None)
    if domain_id is not None:
        env["ROS_DOMAIN_ID"] = str(validate_domain_id(domain_id))
    return env


def configure_this_process(*, domain_id: int | None = None, network: bool | None = None) -> None:
    """Apply :func:`configure_dds_env` to ``os.environ`` (call before ``rclpy.init``)."""
    configure_dds_env(os.environ, domain_id=domain_id, network=network)
