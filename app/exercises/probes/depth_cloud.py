"""Probe ``depth_cloud``: depth images go in; a PointCloud2 of the valid pixels,
back-projected through the pinhole model, must come out.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from app.exercises.probes.base import ProbeContext, draw, register_probe
from app.exercises.probes.topics import SEND_QOS, exchange, fmt, listen, wait_subscribed
from app.exercises.report import Result
from app.lessons.schema import Spec

if TYPE_CHECKING:
    from sensor_msgs.msg import PointCloud2

DEPTH_SIZE = (160, 120)  # width, height
DEPTH_FRAME = "depth_camera_optical_frame"


def _depth_scene(
    rng: np.random.Generator, wall: float, box_depth: float, zero_columns: int, nan_share: float
) -> np.ndarray:
    """A 32FC1 depth image in metres: a slanted wall, a box, and pixels without a reading."""
    width, height = DEPTH_SIZE
    v, u = np.mgrid[0:height, 0:width]
    depth = wall + 0.8 * v / height + 0.3 * u / width  # a wall, tilted
    left, top = int(rng.integers(20, 90)), int(rng.integers(15, 60))
    box = (u >= left) & (u < left + 45) & (v >= top) & (v < top + 40)
    depth[box] = box_depth
    depth[:, :zero_columns] = 0.0  # too close to measure: 0
    depth[rng.random((height, width)) < nan_share] = np.nan  # no echo: NaN
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


def _cloud_verdict(cloud: PointCloud2, depth: np.ndarray, p: Spec, index: int) -> str:
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
            f"{fmt(got[k])}; expected {fmt(want[k])}"
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


@register_probe(
    "depth_cloud",
    required="publish output fx fy cx cy",
    optional="tolerance",
    defaults={
        "images": 2,
        "wall_depth": [1.6, 2.6],
        "box_depth": [0.9, 1.4],
        "zero_columns": [4, 11],
        "nan_share": 0.03,
    },
    words="sends depth images (some pixels without a reading); each answer must be a point "
    "cloud of exactly the valid pixels, back-projected with the camera's fx, fy, cx, cy",
    draws="random depth scenes: a tilted wall (wall_depth), a box at a random place "
    "(box_depth), a strip of zeros (zero_columns wide) and scattered NaN (nan_share)",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    """Send depth images; expect a PointCloud2 of the valid pixels, back-projected."""
    from sensor_msgs.msg import Image, PointCloud2

    from nodes.common.image_conversion import array_to_image

    node = ctx.call.node
    in_topic, out_topic = p["publish"], p["output"]
    name = f"cloud {in_topic} -> {out_topic}"
    publisher = node.create_publisher(Image, in_topic, SEND_QOS)
    monitor = listen(ctx, out_topic, PointCloud2)
    rng = np.random.default_rng(ctx.rng.randrange(2**32))
    try:
        why = wait_subscribed(ctx, publisher, in_topic)
        if why:
            return Result(name, False, why)
        sizes = []
        for index in range(1, int(p["images"]) + 1):
            depth = _depth_scene(
                rng,
                float(draw(ctx.rng, p["wall_depth"])),
                float(draw(ctx.rng, p["box_depth"])),
                int(draw(ctx.rng, p["zero_columns"])),
                float(p["nan_share"]),
            )
            msg = array_to_image(depth, "32FC1")
            msg.header.frame_id = DEPTH_FRAME
            cloud = exchange(ctx, publisher, monitor, msg, index)
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
