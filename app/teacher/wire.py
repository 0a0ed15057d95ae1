"""The classroom-wide topics, their QoS, and messages <-> plain records.

All three topics are reliable and transient local: a teacher page that
starts after the learners still receives each dashboard's latest progress,
and a dashboard that starts after the teacher spoke still gets the latest
notices and settings. Each dashboard keeps only its own last progress
sample; the teacher's reader keeps enough for a whole class arriving at once.
"""

from __future__ import annotations

import re
import time

from builtin_interfaces.msg import Time
from classroom_interfaces.msg import ClassroomSettings, LearnerProgress, TeacherNotice
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from app.teacher import record as rec
from app.teacher.record import LearnerRecord, clip

PROGRESS_TOPIC = "/classroom/progress"
NOTICES_TOPIC = "/classroom/notices"
SETTINGS_TOPIC = "/classroom/settings"
DEFAULT_CLASSROOM_DOMAIN = 101  # far from the learners' own ids (10, 11, ... by default)


def _latched(depth: int) -> QoSProfile:
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        depth=depth,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )


PROGRESS_PUB_QOS = _latched(1)  # a learner's latest state is all anyone needs
PROGRESS_SUB_QOS = _latched(200)  # a late teacher receives up to 40 learners' samples at once
NOTICES_QOS = _latched(10)
SETTINGS_QOS = _latched(1)


def node_name_for(site: str, learner: str) -> str:
    """A ROS node name per learner on the classroom domain (names must be unique there)."""
    return re.sub(r"[^A-Za-z0-9_]", "_", f"classroom_learner_{site}_{learner}")[:200]


def stamp(seconds: float) -> Time:
    whole = int(seconds)
    return Time(sec=whole, nanosec=int((seconds - whole) * 1e9))


def seconds(time_msg: Time) -> float:
    return time_msg.sec + time_msg.nanosec * 1e-9


def to_message(r: LearnerRecord) -> LearnerProgress:
    """Every text clipped to the message's bounds (a long title never fails a publish)."""
    checks = r.check_states[: rec.MAX_CHECKS]
    return LearnerProgress(
        site=clip(r.site, rec.MAX_NAME),
        learner=clip(r.learner, rec.MAX_NAME),
        domain_id=max(0, min(255, r.domain_id)),
        lesson_id=clip(r.lesson_id, rec.MAX_NAME),
        unit=r.unit,
        lesson_title=clip(r.lesson_title, rec.MAX_TITLE),
        step=r.step,
        steps=r.steps,
        step_title=clip(r.step_title, rec.MAX_TITLE),
        steps_passed=r.steps_passed,
        check_states=[clip(s, 8) for s in checks],
        check_reasons=[clip(s, rec.MAX_REASON) for s in r.check_reasons[: len(checks)]],
        exercises_passed=r.exercises_passed,
        exercise_attempts=r.exercise_attempts,
        exercise=clip(r.exercise, rec.MAX_NAME),
        exercise_attempts_here=r.exercise_attempts_here,
        exercise_failed_here=r.exercise_failed_here,
        exercise_passed_here=r.exercise_passed_here,
        exercise_passed_seed=max(0, min(2**32 - 1, r.exercise_passed_seed)),
        exercise_mistake=clip(r.exercise_mistake, rec.MAX_MISTAKE),
        code_excerpt=clip(r.code_excerpt, rec.MAX_CODE),
        last_error=clip(r.last_error, rec.MAX_ERROR),
        nodes_running=[clip(n, rec.MAX_NAME) for n in r.nodes_running[: rec.MAX_NODES]],
        last_activity=stamp(r.last_activity),
        last_progress=stamp(r.last_progress),
    )


def from_message(msg: LearnerProgress, received_at: float | None = None) -> LearnerRecord:
    return LearnerRecord(
        site=msg.site,
        learner=msg.learner,
        domain_id=msg.domain_id,
        lesson_id=msg.lesson_id,
        unit=msg.unit,
        lesson_title=msg.lesson_title,
        step=msg.step,
        steps=msg.steps,
        step_title=msg.step_title,
        steps_passed=msg.steps_passed,
        check_states=tuple(msg.check_states),
        check_reasons=tuple(msg.check_reasons),
        exercises_passed=msg.exercises_passed,
        exercise_attempts=msg.exercise_attempts,
        exercise=msg.exercise,
        exercise_attempts_here=msg.exercise_attempts_here,
        exercise_failed_here=msg.exercise_failed_here,
        exercise_passed_here=msg.exercise_passed_here,
        exercise_passed_seed=msg.exercise_passed_seed,
        exercise_mistake=msg.exercise_mistake,
        code_excerpt=msg.code_excerpt,
        last_error=msg.last_error,
        nodes_running=tuple(msg.nodes_running),
        last_activity=seconds(msg.last_activity),
        last_progress=seconds(msg.last_progress),
        received_at=time.time() if received_at is None else received_at,
    )


def notice(to: str, text: str) -> TeacherNotice:
    return TeacherNotice(
        to=clip(to, 130), text=clip(text, rec.MAX_NOTICE), stamp=stamp(time.time())
    )


def settings(reveal_solution_after: int) -> ClassroomSettings:
    return ClassroomSettings(
        reveal_solution_after=max(0, min(65535, reveal_solution_after)), stamp=stamp(time.time())
    )


__all__ = [
    "ClassroomSettings", "LearnerProgress", "TeacherNotice", "from_message", "to_message",
]  # fmt: skip
