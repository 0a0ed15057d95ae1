"""Probes for the later units: graph resources, images, frames and point clouds.

Each one feeds the learner's node data whose right answer the probe knows
(synthetic images, random points, a depth scene), reads what comes back and
says in numbers what differs: "IoU 0.42 on image 2", "x and y look swapped".
Inputs are built here with numpy, never taken from a catalog node, so a
grade does not depend on timing or on what else runs.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from rclpy.qos import QoSProfile

from app.exercises.probes.base import Probe, ProbeContext
from app.exercises.report import Result
from app.lessons.kinds import make_kind
from app.lessons.schema import Spec
from app.ros.monitor import TopicMonitor
from app.ros.qos import matching_qos

# Reaches reliable and best-effort subscribers alike.
SEND_QOS = QoSProfile(depth=10)
MATCH_WAIT_SEC = 5.0  # for the learner's subscription to appear
ANSWER_WAIT_SEC = 2.0  # for one answer to one input
RESENDS = 3  # an input is sent again when no answer came (discovery may lag)


# -- shared helpers ----------------------------------------------------------


def _split_name(fqn: str) -> tuple[str, str]:
    namespace, _, name = fqn.rpartition("/")
    return namespace or "/", name


def _listen(ctx: ProbeContext, topic: str, msg_type: type) -> TopicMonitor:
    """A reader for the node's answers, reliable when its publisher is (big messages)."""
    qos = matching_qos(ctx.call.node, topic, depth=20)
    return TopicMonitor(ctx.call.node, topic, msg_type, keep=20, qos=qos)


def _wait_subscribed(ctx: ProbeContext, publisher: Any, topic: str) -> str:
    """'' once someone subscribes to ``topic``, else why not."""
    deadline = time.monotonic() + MATCH_WAIT_SEC
    while publisher.get_subscription_count() == 0:
        if time.monotonic() > deadline:
            return f"nothing subscribes to {topic} (waited {MATCH_WAIT_SEC:g} s)"
        ctx.call.sleep(0.05)
    ctx.call.sleep(0.3)  # let the learner's publisher find our reader too
    return ""


def _exchange(
    ctx: ProbeContext, publisher: Any, monitor: TopicMonitor, message: Any, stamp_sec: int
) -> Any | None:
    """Send ``message`` stamped ``stamp_sec`` s and return the answer to it, or None.

    An answer with our stamp belongs to this input. One with a zero stamp (a
    node that does not copy the header) is taken as the answer to the newest
    input. Any other stamp (a late answer to an earlier input, or to someone
    else's) is skipped.
    """
    message.header.stamp.sec, message.header.stamp.nanosec = stamp_sec, 0
    seen = monitor.count
    for _ in range(RESENDS):
        publisher.publish(message)
        deadline = time.monotonic() + ANSWER_WAIT_SEC
        while time.monotonic() < deadline:
            monitor.wait_for_count(seen + 1, 0.1)
            ctx.call.check_cancel()
            for _arrival, answer in monitor.messages_since(seen):
                seen += 1
                stamp = answer.header.stamp
                if stamp.sec == stamp_sec or (stamp.sec == 0 and stamp.nanosec == 0):
                    return answer
    return None


def _fmt(values: Any) -> str:
    return "(" + ", ".join(f"{float(v):.3f}" for v in values) + ")"


# -- publisher_count ---------------------------------------------------------


def publisher_count(ctx: ProbeContext, p: Spec) -> Result:
    """How many publishers the node has on a topic (e.g. none left after cleanup)."""
    target = p.get("node", ctx.learner_node)
    topic, want = p["topic"], p["count"]
    namespace, name = _split_name(target)
    after = f" after {p['after']}" if "after" in p.fields else ""
    deadline = time.monotonic() + p.get("within", 3.0)
    while True:
        got = sum(
            1
            for info in ctx.call.node.get_publishers_info_by_topic(topic)
            if info.node_name == name and info.node_namespace == namespace
        )
        if got == want:
            return Result(
                f"publishers of {target}",
                True,
                f"{target} has {got} publisher(s) on {topic}{after}, as expected",
            )
        if time.monotonic() > deadline:
            return Result(
                f"publishers of {target}",
                False,
                f"{target} has {got} publisher(s) on {topic}{after}; expected {want}",
            )
        ctx.call.sleep(0.2)


# -- point_transform ---------------------------------------------------------


def _pose_matrices(pose: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """(R, t) of a frame placed at x, y, z and turned by fixed-axis roll, pitch, yaw."""
    from nodes.common.frames import rpy_to_matrix

    rotation = rpy_to_matrix(pose["roll"], pose["pitch"], pose["yaw"])
    return rotation, np.array([pose["x"], pose["y"], pose["z"]], dtype=float)


def _transform_slips(pose: dict[str, float]) -> list[tuple[str, Callable[[np.ndarray], Any]]]:
    """The usual ways to get ``p_base = R p + t`` wrong, each with what to say."""
    from nodes.common.frames import rot_x, rot_y, rot_z

    rotation, t = _pose_matrices(pose)
    xyz_order = rot_x(pose["roll"]) @ rot_y(pose["pitch"]) @ rot_z(pose["yaw"])
    return [
        ("the point came back unchanged: it was not transformed", lambda p: p),
        (
            "the translation is missing: add the camera's position (x, y, z) after rotating",
            lambda p: rotation @ p,
        ),
        (
            "the rotation is applied the wrong way round (its transpose, or inverse); "
            "p_base = R @ p_camera + t with R = Rz(yaw) @ Ry(pitch) @ Rx(roll)",
            lambda p: rotation.T @ p + t,
        ),
        (
            "this is the inverse transform (base to camera); the point comes from the "
            "camera, so use T_base_camera itself",
            lambda p: rotation.T @ (p - t),
        ),
        (
            "the rotations are combined in the wrong order; with fixed axes it is "
            "R = Rz(yaw) @ Ry(pitch) @ Rx(roll)",
            lambda p: xyz_order @ p + t,
        ),
        ("no rotation was applied, only the translation", lambda p: p + t),
    ]


def point_transform(ctx: ProbeContext, p: Spec) -> Result:
    """Send random PointStamped in one frame; expect them in another (a fixed pose)."""
    from geometry_msgs.msg import PointStamped

    node = ctx.call.node
    in_topic, out_topic = p["publish"], p["output"]
    pose = {k: float(p["pose"][k]) for k in ("x", "y", "z", "roll", "pitch", "yaw")}
    rotation, t = _pose_matrices(pose)
    tolerance = p.get("tolerance", 1e-3)
    frame = p.get("frame_id", "")
    name = f"transform {in_topic} -> {out_topic}"
    publisher = node.create_publisher(PointStamped, in_topic, SEND_QOS)
    monitor = _listen(ctx, out_topic, PointStamped)
    try:
        why = _wait_subscribed(ctx, publisher, in_topic)
        if why:
            return Result(name, False, why)
        count = p.get("points", 5)
        for i in range(1, count + 1):
            point = np.array(
                [
                    round(ctx.rng.uniform(-0.3, 0.3), 3),
                    round(ctx.rng.uniform(-0.3, 0.3), 3),
                    round(ctx.rng.uniform(0.3, 1.0), 3),
                ]
            )
            msg = PointStamped()
            msg.header.frame_id = p.get("input_frame_id", "camera")
            msg.point.x, msg.point.y, msg.point.z = (float(v) for v in point)
            answer = _exchange(ctx, publisher, monitor, msg, i)
            shown = f"point {i} {_fmt(point)}"
            if answer is None:
                return Result(
                    name, False, f"sent {shown} on {in_topic}; nothing came back on {out_topic}"
                )
            got = np.array([answer.point.x, answer.point.y, answer.point.z])
            want = rotation @ point + t
            error = float(np.linalg.norm(got - want))
            if error > tolerance:
                text = (
                    f"sent {shown}: {out_topic} gave {_fmt(got)}, expected {_fmt(want)} "
                    f"(off by {error:.3f} m)"
                )
                for diagnosis, slip in _transform_slips(pose):
                    if np.linalg.norm(got - np.asarray(slip(point))) <= tolerance:
                        return Result(name, False, f"{text}: {diagnosis}")
                return Result(name, False, text)
            if frame and answer.header.frame_id != frame:
                return Result(
                    name,
                    False,
                    f"the coordinates are right, but header.frame_id is "
                    f"{answer.header.frame_id!r}; expected {frame!r}",
                )
        return Result(
            name, True, f"{count} random points transformed right (within {tolerance:g} m)"
        )
    finally:
        monitor.close()
        node.destroy_publisher(publisher)


# -- image_mask_iou -----------------------------------------------------------

# Scene colours (BGR). Red: hue 2-5 and 172-177 on OpenCV's 0..179 scale,
# saturation and value above 190 even with the noise added; everything else
# is far from any red threshold. The blue shapes are what a node that reads
# bgr8 as RGB takes for red.
LOW_RED = (20, 45, 225)
HIGH_RED = (50, 15, 225)  # red "past 170": hue wraps around at 180
BLUE = (190, 60, 30)
OTHER_COLOURS = (
    (40, 170, 50),  # green
    (30, 210, 220),  # yellow
    (230, 230, 230),  # white
    (25, 25, 25),  # black
    (200, 200, 40),  # cyan
    (190, 40, 190),  # magenta
)
IMAGE_SIZES = ((320, 240), (320, 240), (256, 192))  # width, height
NOISE = 4  # +- grey levels on every channel


class Scene:
    """A synthetic bgr8 image and what is where in it."""

    def __init__(self, width: int, height: int, rng: np.random.Generator) -> None:
        self.rng = rng
        rows = np.linspace(0.0, 1.0, height)[:, None, None]
        base = np.array(rng.choice([(95, 95, 95), (120, 90, 60), (70, 110, 80)]), float)
        self.pixels = base + (rows - 0.5) * 60.0 + np.zeros((height, width, 3))
        self.red = np.zeros((height, width), bool)
        self.high_red = np.zeros((height, width), bool)
        self.blue = np.zeros((height, width), bool)
        for colour in rng.choice(np.array(OTHER_COLOURS), 2, replace=False):
            self.paint(self.shape(), tuple(colour))
        # The blue and the two red shapes never overlap: each stays fully visible.
        taken = np.zeros_like(self.red)
        for colour in (BLUE, LOW_RED, HIGH_RED):
            area = self.shape()
            for _ in range(100):
                if not (area & taken).any():
                    break
                area = self.shape()
            taken |= area
            self.paint(area, colour)
        noise = rng.integers(-NOISE, NOISE + 1, self.pixels.shape)
        self.image = np.clip(self.pixels + noise, 0, 255).astype(np.uint8)

    def shape(self) -> np.ndarray:
        """A random circle or rectangle, 35 to 70 pixels across, inside the image."""
        height, width = self.red.shape
        size = int(self.rng.integers(35, 71))
        left = int(self.rng.integers(0, width - size))
        top = int(self.rng.integers(0, height - size))
        v, u = np.mgrid[0:height, 0:width]
        if self.rng.random() < 0.5:
            centre, radius = (left + size / 2, top + size / 2), size / 2
            return np.asarray((u - centre[0]) ** 2 + (v - centre[1]) ** 2 <= radius**2)
        tall = int(self.rng.integers(size // 2, size + 1))
        return np.asarray((u >= left) & (u < left + size) & (v >= top) & (v < top + tall))

    def paint(self, area: np.ndarray, colour: tuple[int, ...]) -> None:
        self.pixels[area] = colour
        red = colour in (LOW_RED, HIGH_RED)
        self.red = (self.red | area) if red else (self.red & ~area)
        self.high_red = (self.high_red | area) if colour == HIGH_RED else (self.high_red & ~area)
        self.blue = (self.blue | area) if colour == BLUE else (self.blue & ~area)


def _mask_verdict(scene: Scene, mask: np.ndarray, index: int, min_iou: float) -> tuple[float, str]:
    """The mask's IoU with the red pixels, and '' or what is wrong with it."""
    marked = mask > 0
    red = scene.red
    hit = int((marked & red).sum())
    union = int((marked | red).sum())
    iou = hit / union if union else 1.0
    if iou >= min_iou:
        return iou, ""
    n_marked, n_red = int(marked.sum()), int(red.sum())
    text = (
        f"IoU {iou:.2f} on image {index} (expected >= {min_iou:.2f}): the mask marks "
        f"{n_marked} pixels, {hit} of the {n_red} red ones"
    )
    blue = scene.blue.sum()
    high = scene.high_red.sum()
    found_high = (marked & scene.high_red).sum() / high if high else 1.0
    found_low = (marked & red & ~scene.high_red).sum() / max(1, (red & ~scene.high_red).sum())
    if blue and (marked & scene.blue).sum() > 0.5 * blue and hit < 0.5 * n_red:
        return iou, text + (
            ": it marks the blue shapes instead of the red ones, as if the image were in "
            "RGB order; bgr8 (like OpenCV) stores blue first, so convert with COLOR_BGR2HSV"
        )
    if found_high < 0.3 and found_low > 0.7:
        return iou, text + (
            ": it misses the red whose hue is near 179; red wraps around the hue circle, "
            "so it needs two ranges (0-10 and 170-179) joined with |"
        )
    if n_red and n_marked > 2 * n_red:
        return iou, text + f": the mask covers {n_marked / n_red:.1f} times too many pixels"
    if hit < 0.5 * n_red:
        return iou, text + ": it misses most of the red pixels"
    return iou, text


def image_mask_iou(ctx: ProbeContext, p: Spec) -> Result:
    """Send synthetic bgr8 images with red shapes; expect mono8 masks of the red pixels."""
    from sensor_msgs.msg import Image

    from nodes.common.image_conversion import array_to_image, image_to_array

    node = ctx.call.node
    in_topic, out_topic = p["publish"], p["output"]
    min_iou = p.get("min_iou", 0.9)
    name = f"red mask {in_topic} -> {out_topic}"
    publisher = node.create_publisher(Image, in_topic, SEND_QOS)
    monitor = _listen(ctx, out_topic, Image)
    rng = np.random.default_rng(ctx.rng.randrange(2**32))
    try:
        why = _wait_subscribed(ctx, publisher, in_topic)
        if why:
            return Result(name, False, why)
        scores = []
        for index, (width, height) in enumerate(IMAGE_SIZES, start=1):
            scene = Scene(width, height, rng)
            msg = array_to_image(scene.image, "bgr8")
            msg.header.frame_id = "camera"
            answer = _exchange(ctx, publisher, monitor, msg, index)
            if answer is None:
                return Result(
                    name, False, f"sent image {index} on {in_topic}; no mask came on {out_topic}"
                )
            if answer.encoding != "mono8":
                return Result(
                    name,
                    False,
                    f"image {index}: the mask's encoding is {answer.encoding!r}; expected "
                    "'mono8' (one byte per pixel: 255 where red, 0 elsewhere)",
                )
            if (answer.width, answer.height) != (width, height):
                return Result(
                    name,
                    False,
                    f"image {index}: the mask is {answer.width}x{answer.height}; "
                    f"the image was {width}x{height}",
                )
            iou, verdict = _mask_verdict(scene, image_to_array(answer), index, min_iou)
            if verdict:
                return Result(name, False, verdict)
            scores.append(iou)
        shown = ", ".join(f"{s:.2f}" for s in scores)
        return Result(name, True, f"{len(scores)} masks, IoU {shown} (at least {min_iou:.2f})")
    finally:
        monitor.close()
        node.destroy_publisher(publisher)


# -- depth_cloud ---------------------------------------------------------------

DEPTH_SIZE = (160, 120)  # width, height
DEPTH_FRAME = "depth_camera_optical_frame"


def _depth_scene(rng: np.random.Generator) -> np.ndarray:
    """A 32FC1 depth image in metres: a slanted wall, a box, and pixels without a reading."""
    width, height = DEPTH_SIZE
    v, u = np.mgrid[0:height, 0:width]
    depth = 2.0 + 0.8 * v / height + 0.3 * u / width  # a wall, tilted
    left, top = int(rng.integers(20, 90)), int(rng.integers(15, 60))
    box = (u >= left) & (u < left + 45) & (v >= top) & (v < top + 40)
    depth[box] = round(float(rng.uniform(0.9, 1.4)), 3)
    depth[:, : int(rng.integers(4, 12))] = 0.0  # too close to measure: 0
    depth[rng.random((height, width)) < 0.03] = np.nan  # no echo: NaN
    return depth.astype(np.float32)


def _max_error(a: np.ndarray, b: np.ndarray) -> float:
    """The largest coordinate difference; infinite when a value is NaN or infinite."""
    error = np.abs(np.asarray(a, float) - np.asarray(b, float))
    if not error.size:
        return 0.0
    return float(error.max()) if np.isfinite(error).all() else math.inf


def _cloud_slips(
    u: np.ndarray, v: np.ndarray, z: np.ndarray, fx: float, fy: float, cx: float, cy: float
) -> list[tuple[str, np.ndarray]]:
    """The usual ways to get the pinhole back-projection wrong, each with what to say."""
    return [
        (
            "x and y are not multiplied by the depth: x = (u - cx) * z / fx",
            np.stack([(u - cx) / fx, (v - cy) / fy, z], axis=1),
        ),
        (
            "x and y look swapped: x comes from the column u, y from the row v",
            np.stack([(v - cy) * z / fy, (u - cx) * z / fx, z], axis=1),
        ),
        (
            "the principal point (cx, cy) was not subtracted from u and v",
            np.stack([u * z / fx, v * z / fy, z], axis=1),
        ),
    ]


def _same_in_another_order(
    got: np.ndarray,
    depth: np.ndarray,
    fx: float,
    fy: float,
    cx: float,
    cy: float,
    tolerance: float,
) -> bool:
    """Whether ``got`` holds each valid pixel's point once, in whatever order.

    Each point is projected back to its pixel (u = fx x / z + cx, ...), so a
    right point finds its own pixel; sorting would pair up near-equal points
    wrongly.
    """
    height, width = depth.shape
    with np.errstate(divide="ignore", invalid="ignore"):
        z = got[:, 2].astype(float)
        u = np.rint(got[:, 0] * fx / z + cx)
        v = np.rint(got[:, 1] * fy / z + cy)
    inside = np.isfinite(u) & np.isfinite(v) & (u >= 0) & (u < width) & (v >= 0) & (v < height)
    if not inside.all():
        return False
    u, v = u.astype(int), v.astype(int)
    if len(np.unique(v * width + u)) != len(got):
        return False
    d = depth[v, u].astype(float)
    if not (np.isfinite(d) & (d > 0)).all():
        return False
    want = np.stack([(u - cx) * d / fx, (v - cy) * d / fy, d], axis=1)
    return _max_error(got, want) <= tolerance


def _cloud_verdict(cloud: Any, depth: np.ndarray, p: Spec, index: int) -> str:
    """'' when the cloud holds exactly the back-projected valid pixels, else what differs."""
    from nodes.common.pointcloud import pointcloud2_to_xyz_rgb

    fx, fy, cx, cy = (float(p[k]) for k in ("fx", "fy", "cx", "cy"))
    tolerance = p.get("tolerance", 1e-3)
    names = [field.name for field in cloud.fields]
    if not {"x", "y", "z"} <= set(names):
        return f"image {index}: the cloud's fields are {names}; it needs x, y and z (float32)"
    try:
        got, _colours = pointcloud2_to_xyz_rgb(cloud, skip_nans=False)
    except ValueError as exc:
        return f"image {index}: cannot read the cloud: {exc}"
    v, u = np.nonzero(np.isfinite(depth) & (depth > 0))  # row-major, as a loop over v, u
    z = depth[v, u].astype(float)
    want = np.stack([(u - cx) * z / fx, (v - cy) * z / fy, z], axis=1)
    total, zeros = depth.size, int((depth == 0).sum())
    if len(got) != len(want):
        text = (
            f"image {index}: the cloud has {len(got)} points; {len(want)} of the {total} "
            "pixels have a depth reading"
        )
        if len(got) in (total, total - zeros, len(want) + zeros):
            text += "; pixels with depth 0 or NaN have no reading and must be left out"
        return text
    if _max_error(got, want) > tolerance:
        if _same_in_another_order(got, depth, fx, fy, cx, cy, tolerance):
            return ""
        k = int(np.argmax(np.nan_to_num(np.abs(got - want), nan=np.inf).max(axis=1)))
        text = (
            f"image {index}: the point of pixel u={u[k]}, v={v[k]} (depth {z[k]:.3f} m) is "
            f"{_fmt(got[k])}; expected {_fmt(want[k])}"
        )
        for diagnosis, slip in _cloud_slips(u, v, z, fx, fy, cx, cy):
            if _max_error(got, slip) <= tolerance:
                return f"{text}: {diagnosis}"
        return text
    if cloud.header.frame_id != DEPTH_FRAME:
        return (
            f"image {index}: the points are right, but the cloud's frame_id is "
            f"{cloud.header.frame_id!r}; keep the image's header ({DEPTH_FRAME!r})"
        )
    return ""


def depth_cloud(ctx: ProbeContext, p: Spec) -> Result:
    """Send depth images; expect a PointCloud2 of the valid pixels, back-projected."""
    from sensor_msgs.msg import Image, PointCloud2

    from nodes.common.image_conversion import array_to_image

    node = ctx.call.node
    in_topic, out_topic = p["publish"], p["output"]
    name = f"cloud {in_topic} -> {out_topic}"
    publisher = node.create_publisher(Image, in_topic, SEND_QOS)
    monitor = _listen(ctx, out_topic, PointCloud2)
    rng = np.random.default_rng(ctx.rng.randrange(2**32))
    try:
        why = _wait_subscribed(ctx, publisher, in_topic)
        if why:
            return Result(name, False, why)
        sizes = []
        for index in range(1, p.get("images", 2) + 1):
            depth = _depth_scene(rng)
            msg = array_to_image(depth, "32FC1")
            msg.header.frame_id = DEPTH_FRAME
            cloud = _exchange(ctx, publisher, monitor, msg, index)
            if cloud is None:
                return Result(
                    name, False, f"sent depth image {index}; no cloud came on {out_topic}"
                )
            verdict = _cloud_verdict(cloud, depth, p, index)
            if verdict:
                return Result(name, False, verdict)
            sizes.append(str(cloud.width * cloud.height))
        return Result(
            name, True, f"{len(sizes)} clouds ({', '.join(sizes)} points) match the depth images"
        )
    finally:
        monitor.close()
        node.destroy_publisher(publisher)


# Each kind's fields (the loader validates against them) and its code.
# What these kinds draw at grading time (from the probe's seed), for `exercise explain`.
DRAWS = {
    "image_mask_iou": "random images (background, two other colours, red shapes 35-70 px)",
    "depth_cloud": "random depth scenes (a box at 0.9-1.4 m, invalid pixels)",
    "point_transform": "random points (x, y in [-0.3, 0.3] m, z in [0.3, 1.0] m)",
}
KINDS = {
    "publisher_count": make_kind("topic count", "node after within"),
    "image_mask_iou": make_kind("publish output", "min_iou"),
    "depth_cloud": make_kind("publish output fx fy cx cy", "images tolerance"),
    "point_transform": make_kind("publish output pose", "points tolerance frame_id input_frame_id"),
}
PROBES: dict[str, Probe] = {
    "publisher_count": publisher_count,
    "point_transform": point_transform,
    "image_mask_iou": image_mask_iou,
    "depth_cloud": depth_cloud,
}
