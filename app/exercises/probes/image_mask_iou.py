"""Probe ``image_mask_iou``: synthetic bgr8 images with red shapes go in; mono8 masks of the
red pixels must come out (IoU), with the usual slips (RGB order, one hue range) named.
"""

from __future__ import annotations

import numpy as np

from app.exercises.probes.base import ProbeContext, draw, register_probe
from app.exercises.probes.topics import SEND_QOS, exchange, listen, wait_subscribed
from app.exercises.report import Result
from app.lessons.schema import Spec

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
NOISE = 4  # +- grey levels on every channel


class Scene:
    """A synthetic bgr8 image and what is where in it."""

    def __init__(
        self,
        width: int,
        height: int,
        rng: np.random.Generator,
        shape_px: tuple[int, int] = (35, 70),
    ) -> None:
        self.rng = rng
        self.shape_px = shape_px
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
        """A random circle or rectangle, ``shape_px`` pixels across, inside the image."""
        height, width = self.red.shape
        size = int(self.rng.integers(self.shape_px[0], self.shape_px[1] + 1))
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


@register_probe(
    "image_mask_iou",
    required="publish output",
    optional="min_iou",
    defaults={"images": 3, "width": [240, 360], "height": [180, 270], "shape_px": [35, 70]},
    words="sends synthetic camera images with red shapes; each answer must be a mono8 mask "
    "whose overlap (IoU) with the red pixels is high enough",
    draws="random images of random size (width, height): a shaded background, two other "
    "colours, a blue shape and two red ones (shape_px across)",
)
def run(ctx: ProbeContext, p: Spec) -> Result:
    """Send synthetic bgr8 images with red shapes; expect mono8 masks of the red pixels."""
    from sensor_msgs.msg import Image

    from nodes.common.image_conversion import array_to_image, image_to_array

    node = ctx.call.node
    in_topic, out_topic = p["publish"], p["output"]
    min_iou = p.get("min_iou", 0.9)
    name = f"red mask {in_topic} -> {out_topic}"
    publisher = node.create_publisher(Image, in_topic, SEND_QOS)
    monitor = listen(ctx, out_topic, Image)
    rng = np.random.default_rng(ctx.rng.randrange(2**32))
    try:
        why = wait_subscribed(ctx, publisher, in_topic)
        if why:
            return Result(name, False, why)
        scores = []
        low, high = (int(v) for v in p["shape_px"])
        if low < 4 or high < low:
            raise ValueError(f"shape_px must be [low, high], 4 <= low <= high: {p['shape_px']}")
        for index in range(1, int(p["images"]) + 1):
            width, height = int(draw(ctx.rng, p["width"])), int(draw(ctx.rng, p["height"]))
            if min(width, height) <= high:
                raise ValueError(f"an image of {width}x{height} cannot hold shapes of {high} px")
            scene = Scene(width, height, rng, (low, high))
            msg = array_to_image(scene.image, "bgr8")
            msg.header.frame_id = "camera"
            answer = exchange(ctx, publisher, monitor, msg, index)
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
