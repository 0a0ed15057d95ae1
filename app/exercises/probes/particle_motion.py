"""Probe ``particle_motion``: a particle filter's motion update, judged by its statistics.

The node keeps the newest set of particles from ``particles``
(``geometry_msgs/msg/PoseArray``) and, for each odometry message on ``odom``
(``nav_msgs/msg/Odometry``) after the first, moves every particle by the
odometry's step with noise (*Probabilistic Robotics*' odometry motion model:
a turn ``rot1``, a straight move ``trans``, a turn ``rot2``, each with its own
Gaussian noise whose variance grows with the motion by ``alpha1..alpha4``) and
publishes the moved set on ``output``, stamped as the odometry message.

For each trial the grader sends a random cloud of particles, then an odometry
pose a random step away from the last one. Each moved particle is taken apart
into the turn, move and turn that lead to it from its own old pose: the
noise the node gave it. Over the cloud, each of the three must average the
odometry's value (within five standard errors) and spread as the model says
(``spread_low`` to ``spread_high`` times its standard deviation); a node that
moved every particle alike, or exactly, is told so. The clouds and the steps
are pure functions of the grading's random generator (testable without ROS).
"""

from __future__ import annotations

import math
import random
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from app.exercises.probes.base import ProbeContext, draw, register_probe
from app.exercises.probes.topics import (
    listen,
    publishers_note,
    wait_matched,
    with_note,
)
from app.exercises.report import Result
from app.lessons.schema import Spec

if TYPE_CHECKING:
    from geometry_msgs.msg import Pose, PoseArray
    from nav_msgs.msg import Odometry
    from numpy.typing import ArrayLike, NDArray

Pose2D = tuple[float, float, float]  # x, y, yaw
PARTS = ("rot1", "trans", "rot2")
UNITS = {"rot1": "rad", "trans": "m", "rot2": "rad"}


def wrap(angle: ArrayLike) -> NDArray[np.float64] | np.float64:
    """An angle (or an array of them) in [-pi, pi)."""
    return (np.asarray(angle) + math.pi) % (2.0 * math.pi) - math.pi


@dataclass(frozen=True)
class Motion:
    """The odometry's step from one pose to the next: turn, move, turn."""

    rot1: float
    trans: float
    rot2: float

    @classmethod
    def between(cls, a: Pose2D, b: Pose2D) -> Motion:
        dx, dy = b[0] - a[0], b[1] - a[1]
        rot1 = float(wrap(math.atan2(dy, dx) - a[2]))
        return cls(rot1, math.hypot(dx, dy), float(wrap(b[2] - a[2] - rot1)))

    def after(self, a: Pose2D) -> Pose2D:
        heading = a[2] + self.rot1
        return (
            a[0] + self.trans * math.cos(heading),
            a[1] + self.trans * math.sin(heading),
            float(wrap(heading + self.rot2)),
        )

    def sigmas(self, alphas: Sequence[float]) -> tuple[float, float, float]:
        """The standard deviations of the noise on rot1, trans and rot2 (the statement's)."""
        a1, a2, a3, a4 = alphas
        r1, t, r2 = self.rot1, self.trans, self.rot2
        return (
            math.sqrt(a1 * r1 * r1 + a2 * t * t),
            math.sqrt(a3 * t * t + a4 * (r1 * r1 + r2 * r2)),
            math.sqrt(a1 * r2 * r2 + a2 * t * t),
        )


@dataclass(frozen=True)
class Trial:
    particles: np.ndarray  # (N, 3): x, y, yaw in the map frame
    odom: Pose2D  # the odometry pose sent after them
    motion: Motion  # from the odometry pose before to ``odom``


def draw_motion(rng: random.Random) -> Motion:
    """A step forwards with turns of 0.2 to 0.6 rad either way (never a half turn)."""

    def turn() -> float:
        return rng.choice((-1.0, 1.0)) * rng.uniform(0.2, 0.6)

    return Motion(turn(), rng.uniform(0.4, 1.0), turn())


def draw_trial(rng: random.Random, last_odom: Pose2D, count: int) -> Trial:
    """A cloud of ``count`` particles whose headings differ from the odometry's by 0.7 to
    1.6 rad (the map and odom frames are turned), and the next odometry pose."""
    heading = last_odom[2] + rng.choice((-1.0, 1.0)) * rng.uniform(0.7, 1.6)
    cx, cy = rng.uniform(-4.0, 4.0), rng.uniform(-4.0, 4.0)
    gen = np.random.default_rng(rng.getrandbits(32))
    particles = np.column_stack(
        [
            gen.normal(cx, 0.3, count),
            gen.normal(cy, 0.3, count),
            wrap(gen.normal(heading, 0.3, count)),
        ]
    ).round(4)
    step = draw_motion(rng)
    odom = tuple(round(v, 4) for v in step.after(last_odom))
    assert len(odom) == 3
    return Trial(particles, odom, Motion.between(last_odom, odom))


def first_odom(rng: random.Random) -> Pose2D:
    return (
        round(rng.uniform(-2.0, 2.0), 4),
        round(rng.uniform(-2.0, 2.0), 4),
        round(rng.uniform(-math.pi, math.pi), 4),
    )


def taken_apart(before: np.ndarray, after: np.ndarray, motion: Motion) -> np.ndarray:
    """(N, 3): each particle's turn, move and turn from its old pose to its new one, minus
    the odometry's. A short move that points back (its noisy length came out negative) is
    read as one, not as a half turn; a move as long as the odometry's that points
    elsewhere is not (it went the wrong way)."""
    dx, dy = after[:, 0] - before[:, 0], after[:, 1] - before[:, 1]
    trans = np.hypot(dx, dy)
    rot1 = wrap(np.arctan2(dy, dx) - before[:, 2])
    back = (np.abs(wrap(rot1 - motion.rot1)) > math.pi / 2) & (trans < motion.trans / 2)
    rot1 = np.where(back, wrap(rot1 + math.pi), rot1)
    trans = np.where(back, -trans, trans)
    rot2 = wrap(after[:, 2] - before[:, 2] - rot1)
    return np.column_stack(
        [wrap(rot1 - motion.rot1), trans - motion.trans, wrap(rot2 - motion.rot2)]
    )


def judge_moved(
    before: np.ndarray,
    after: np.ndarray,
    frame_id: str,
    motion: Motion,
    alphas: Sequence[float],
    spread: tuple[float, float],
) -> tuple[str, str]:
    """(why the moved set breaks the model or '' when it keeps it, what was measured)."""
    n = len(before)
    if len(after) != n:
        return (
            f"the answer has {len(after)} poses for {n} particles: move each particle and "
            "send them all back, in the same order",
            "",
        )
    if frame_id != "map":
        return f"the answer's header.frame_id is {frame_id!r}; the particles are in 'map'", ""
    moved = float(np.hypot(after[:, 0] - before[:, 0], after[:, 1] - before[:, 1]).mean())
    if moved < 0.01:
        return (
            f"the particles did not move (by {moved:.3f} m on average); the odometry moved "
            f"{motion.trans:.2f} m",
            "",
        )
    error = taken_apart(before, after, motion)
    sigmas = motion.sigmas(alphas)
    mean, std = error.mean(axis=0), error.std(axis=0)
    found = "; ".join(
        f"{part} {want:+.3f} {UNITS[part]}: mean error {m:+.4f}, spread {s:.4f} (model {sd:.4f})"
        for part, want, m, s, sd in zip(
            PARTS, (motion.rot1, motion.trans, motion.rot2), mean, std, sigmas, strict=True
        )
    )
    if (std < 1e-6).all():
        if (np.abs(mean) < 1e-6).all():
            return (
                "every particle moved exactly by the odometry's step: no noise was added, so "
                "the cloud will never spread to cover what the wheels got wrong",
                found,
            )
        return (
            "all particles moved alike, by the same noisy step: draw the noise for each "
            f"particle on its own, not once for the whole set ({found})",
            found,
        )
    for i, part in enumerate(PARTS):
        bound = 5.0 * sigmas[i] / math.sqrt(n) + 0.002
        if abs(mean[i]) <= bound:
            continue
        if part == "rot1":
            why = (
                f"the particles set off in the wrong direction: {mean[i]:+.2f} rad on average "
                f"from each particle's own heading turned by rot1 ({motion.rot1:.2f} rad). "
                "Move each particle along its own heading + rot1, not the odometry's"
            )
        elif part == "trans":
            why = (
                f"the particles moved {motion.trans + mean[i]:.3f} m on average; the odometry "
                f"moved {motion.trans:.3f} m"
            )
        else:
            why = (
                f"the particles' new headings are off by {mean[i]:+.2f} rad on average: the new "
                "heading is the old one + rot1 + rot2 (each with its noise)"
            )
        return why, found
    low, high = spread
    for i, part in enumerate(PARTS):
        ratio = std[i] / sigmas[i]
        if low <= ratio <= high:
            continue
        formula = (
            "alpha3 * trans^2 + alpha4 * (rot1^2 + rot2^2)"
            if part == "trans"
            else f"alpha1 * {part}^2 + alpha2 * trans^2"
        )
        return (
            f"the spread of {part} over the particles is {std[i]:.4f} {UNITS[part]}; the model's "
            f"is {sigmas[i]:.4f} (its square is {formula}: that is the variance, the standard "
            "deviation is its square root)",
            found,
        )
    return "", found


def odom_message(pose: Pose2D, sec: int) -> Odometry:
    """The ``nav_msgs/msg/Odometry`` the grader sends for an odometry pose, stamped ``sec``."""
    from nav_msgs.msg import Odometry

    msg = Odometry()
    msg.header.frame_id, msg.child_frame_id = "odom", "base_link"
    msg.header.stamp.sec = sec
    msg.pose.pose.position.x, msg.pose.pose.position.y = pose[0], pose[1]
    msg.pose.pose.orientation.z = math.sin(pose[2] / 2.0)
    msg.pose.pose.orientation.w = math.cos(pose[2] / 2.0)
    return msg


def cloud_message(particles: np.ndarray) -> PoseArray:
    """The ``geometry_msgs/msg/PoseArray`` of a cloud of particles, in the map frame."""
    from geometry_msgs.msg import Pose, PoseArray

    msg = PoseArray()
    msg.header.frame_id = "map"
    for x, y, yaw in particles:
        pose = Pose()
        pose.position.x, pose.position.y = float(x), float(y)
        pose.orientation.z, pose.orientation.w = math.sin(yaw / 2.0), math.cos(yaw / 2.0)
        msg.poses.append(pose)
    return msg


def poses_of(msg: PoseArray) -> np.ndarray:
    """(N, 3): the x, y and yaw of each pose of a ``PoseArray``."""
    return np.array([_pose2d(pose) for pose in msg.poses], dtype=float).reshape(-1, 3)


def _pose2d(pose: Pose) -> Pose2D:
    q = pose.orientation
    yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
    return pose.position.x, pose.position.y, yaw


@register_probe(
    "particle_motion",
    required="output",
    optional="particles odom",
    defaults={
        "count": [300, 500],
        "trials": 3,
        "alphas": [0.05, 0.01, 0.02, 0.01],
        "spread_low": 0.75,
        "spread_high": 1.33,
    },
    words="sends clouds of particles and odometry poses a step apart; each particle the node "
    "moves is taken apart into the turn, move and turn from its old pose: over the cloud their "
    "means must be the odometry's and their spread the noise model's",
    draws="the clouds of particles (where, which way, how many), the odometry's first pose and "
    "each step (turn, move, turn)",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    from geometry_msgs.msg import PoseArray
    from nav_msgs.msg import Odometry
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    particles_topic, odom_topic = p.get("particles", "/particles"), p.get("odom", "/odom")
    output = p["output"]
    alphas = [float(a) for a in p["alphas"]]
    low, high = float(p["spread_low"]), float(p["spread_high"])
    trials = int(p["trials"])
    name = f"particles moved on {output}"
    node = ctx.call.node
    reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    cloud_pub = node.create_publisher(PoseArray, particles_topic, reliable)
    odom_pub = node.create_publisher(Odometry, odom_topic, reliable)
    answers = listen(ctx, output, PoseArray)
    stamp = [0]

    def send_odom(pose: Pose2D) -> int:
        stamp[0] += 1
        odom_pub.publish(odom_message(pose, stamp[0]))
        return stamp[0]

    def answer_to(sec: int, seen: int) -> PoseArray | None:
        deadline = time.monotonic() + 3.0
        while time.monotonic() < deadline:
            answers.wait_for_count(seen + 1, 0.1)
            ctx.call.check_cancel()
            for _arrival, msg in answers.messages_since(seen):
                seen += 1
                got = msg.header.stamp
                if got.sec == sec or (got.sec == 0 and got.nanosec == 0):
                    return msg
        return None

    try:
        waited = wait_matched(ctx, ((cloud_pub, particles_topic), (odom_pub, odom_topic)), output)
        if waited:
            return Result(name, False, waited)
        # The first odometry pose only starts the count (the first cloud may come before it
        # or after: either way no answer is due for it).
        last = first_odom(ctx.rng)
        send_odom(last)
        done: list[str] = []
        before_count = 0
        for number in range(1, trials + 1):
            count = int(draw(ctx.rng, p["count"]))
            if count == before_count:
                count += 1
            for attempt in range(2):
                origin = last
                trial = draw_trial(ctx.rng, origin, count)
                cloud_pub.publish(cloud_message(trial.particles))
                ctx.call.sleep(0.15 + 0.5 * attempt)  # the cloud arrives before the odometry
                seen = answers.count
                sec = send_odom(trial.odom)
                last = trial.odom
                answer = answer_to(sec, seen)
                stale = answer is not None and len(answer.poses) == before_count != count
                if answer is not None and not stale:
                    break
            m = trial.motion
            what = (
                f"trial {number}: {count} particles, then odometry from "
                f"({_fmt(origin)}) by rot1 {m.rot1:+.2f} rad, "
                f"trans {m.trans:.2f} m, rot2 {m.rot2:+.2f} rad"
            )
            if answer is None:
                text = f"{what}: no answer on {output} within 3 s"
                return Result(name, False, with_note(text, publishers_note(node, output, _TYPE)))
            if stale:
                return Result(
                    name,
                    False,
                    f"{what}: the answer has the {before_count} particles of the previous "
                    "trial: keep the newest set that came on /particles",
                )
            after = poses_of(answer)
            why, found = judge_moved(
                trial.particles, after, answer.header.frame_id, m, alphas, (low, high)
            )
            if why:
                return Result(name, False, f"{what}: {why}")
            done.append(f"trial {number}: {found}")
            before_count = count
        return Result(name, True, "; ".join(done))
    finally:
        answers.close()
        node.destroy_publisher(cloud_pub)
        node.destroy_publisher(odom_pub)


def _fmt(pose: Pose2D) -> str:
    return f"{pose[0]:.2f}, {pose[1]:.2f}, yaw {pose[2]:.2f}"


_TYPE = "geometry_msgs/msg/PoseArray"
