"""A second ROS participant on another domain: one context, one node, one executor thread.

A learner's dashboard lives in the learner's own ROS domain, so that nobody's
nodes show up in anybody else's graph. The classroom's shared traffic (each
learner's progress, the teacher's notices) needs a domain that every learner
and the teacher share. Rather than open that domain to the learner's nodes,
the dashboard joins it with a separate, small participant: its node serves
no parameters and writes no /rosout, so the shared domain carries only the
classroom's own topics.
"""

from __future__ import annotations

from app.dds import validate_domain_id
from app.ros.runtime import RosRuntime


class SideParticipant(RosRuntime):
    """A quiet ``node`` on ``domain_id``, spun by its own executor thread until ``shutdown``."""

    def __init__(self, node_name: str, domain_id: int) -> None:
        self.domain_id = validate_domain_id(domain_id)
        super().__init__(node_name, domain_id=self.domain_id, quiet=True)
