"""Inside the ``classroom`` command: every learner's latest progress, and the teacher's voice.

The progress subscription's callback (the side participant's executor
thread) only records the newest record per learner under a lock; readers get
an immutable copy. Notices and settings are published from whichever thread
the teacher's click ran on (publishing is thread-safe in rclpy).
"""

from __future__ import annotations

import threading

from app.ros.side_participant import SideParticipant
from app.teacher import wire
from app.teacher.record import LearnerRecord

TEACHER_NODE = "classroom_teacher"


class Roster:
    def __init__(self, classroom_domain: int, node_name: str = TEACHER_NODE) -> None:
        self._lock = threading.Lock()
        self._records: dict[str, LearnerRecord] = {}
        self.received = 0
        self._side = SideParticipant(node_name, classroom_domain)
        node = self._side.node
        node.create_subscription(
            wire.LearnerProgress, wire.PROGRESS_TOPIC, self._on_progress, wire.PROGRESS_SUB_QOS
        )
        self._notices = node.create_publisher(
            wire.TeacherNotice, wire.NOTICES_TOPIC, wire.NOTICES_QOS
        )
        self._settings = node.create_publisher(
            wire.ClassroomSettings, wire.SETTINGS_TOPIC, wire.SETTINGS_QOS
        )

    def _on_progress(self, msg: wire.LearnerProgress) -> None:
        record = wire.from_message(msg)
        with self._lock:
            self._records[record.key] = record
            self.received += 1

    def records(self) -> list[LearnerRecord]:
        with self._lock:
            return list(self._records.values())

    def send_notice(self, to: str, text: str) -> None:
        """``to``: a learner's key ("site/learner"), or '' for everyone."""
        self._notices.publish(wire.notice(to, text))

    def set_reveal_after(self, failed_checks: int) -> None:
        """0: each exercise's own number."""
        self._settings.publish(wire.settings(failed_checks))

    def close(self) -> None:
        self._side.shutdown()
