"""Reading and writing the map's image: netpbm (PGM, PPM) here, other formats through Pillow.

Nav2 reads and writes images with GraphicsMagick, so a map image may be any
format it knows; map_saver writes PGM unless told otherwise. We read and
write PGM and PPM ourselves (binary P5/P6 and plain P2/P3, 8 or 16 bits) and
hand PNG, BMP and the rest to Pillow. A colour image becomes grey as
GraphicsMagick makes it: 0.299 R + 0.587 G + 0.114 B.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

NETPBM = {"pgm", "ppm", "pnm"}
_TOKEN = re.compile(rb"(?:\s|#[^\n]*\n?)*(\S+)")


class ImageError(ValueError):
    """An image that cannot be read or written; the message says why."""


def _tokens(data: bytes, count: int, at: int = 0) -> tuple[list[bytes], int]:
    found = []
    for _ in range(count):
        match = _TOKEN.match(data, at)
        if match is None:
            raise ImageError("the netpbm header ends early")
        found.append(match.group(1))
        at = match.end()
    return found, at


def _read_netpbm(data: bytes) -> tuple[np.ndarray, np.ndarray | None]:
    magic = data[:2]
    if magic not in (b"P2", b"P3", b"P5", b"P6"):
        raise ImageError(f"not a PGM or PPM image (starts with {data[:2]!r})")
    try:
        (width, height, maxval), at = _tokens(data, 3, 2)
        w, h, top = int(width), int(height), int(maxval)
    except ValueError:
        raise ImageError("the netpbm header's width, height or maxval is not a number") from None
    if w <= 0 or h <= 0 or not 0 < top < 65536:
        raise ImageError(f"a netpbm image of {w} x {h} with maxval {top} makes no sense")
    channels = 3 if magic in (b"P3", b"P6") else 1
    count = w * h * channels
    if magic in (b"P5", b"P6"):
        start = at + 1  # one whitespace byte after maxval
        dtype = np.dtype(">u2") if top > 255 else np.dtype(np.uint8)
        raw = data[start : start + count * dtype.itemsize]
        if len(raw) < count * dtype.itemsize:
            raise ImageError(f"the image data is short: {len(raw)} bytes for {w} x {h} pixels")
        values = np.frombuffer(raw, dtype).astype(np.float64)
    else:
        try:
            values = np.array(data[at:].split()[:count], dtype=np.float64)
        except ValueError:
            raise ImageError("a plain netpbm image holds something that is not a number") from None
        if len(values) < count:
            raise ImageError(f"the image data is short: {len(values)} values for {w} x {h}")
    values = np.rint(values * 255.0 / top).reshape(h, w, channels)
    if channels == 3:
        return _grey(values), None
    return values[:, :, 0].astype(np.uint8), None


def _grey(rgb: np.ndarray) -> np.ndarray:
    r, g, b = (rgb[:, :, i].astype(np.float64) for i in range(3))
    return np.clip(np.rint(0.299 * r + 0.587 * g + 0.114 * b), 0, 255).astype(np.uint8)


def read_image(path: str | Path) -> tuple[np.ndarray, np.ndarray | None]:
    """(grey (H, W) uint8, alpha (H, W) uint8 or None) of an image file; row 0 is the top."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise ImageError(f"unable to open image '{path}': no such file") from None
    except OSError as exc:
        raise ImageError(f"unable to open image '{path}': {exc.strerror or exc}") from None
    if data[:1] == b"P" and data[1:2] in b"123456":
        return _read_netpbm(data)
    try:
        from PIL import Image
    except ImportError:
        raise ImageError(f"'{path.name}' is not PGM/PPM, and Pillow is not installed") from None
    try:
        with Image.open(path) as image:
            image.load()
            alpha = None
            if image.mode in ("RGBA", "LA", "PA") or "transparency" in image.info:
                alpha = np.asarray(image.convert("RGBA"))[:, :, 3].copy()
            if image.mode in ("I;16", "I;16B", "I"):
                grey = np.rint(np.asarray(image, np.float64) * 255.0 / 65535.0)
                return np.clip(grey, 0, 255).astype(np.uint8), alpha
            rgb = np.asarray(image.convert("RGB"))
            return _grey(rgb), alpha
    except (OSError, ValueError, SyntaxError) as exc:
        raise ImageError(f"unable to read image '{path}': {exc}") from None


def writable(fmt: str) -> bool:
    """Whether an image of this format (a file extension) can be written here."""
    if fmt in NETPBM:
        return True
    try:
        from PIL import Image
    except ImportError:
        return False
    extension = f".{fmt}"
    return extension in Image.registered_extensions() and (
        Image.registered_extensions()[extension] in Image.SAVE
    )


def write_image(path: str | Path, grey: np.ndarray, alpha: np.ndarray | None = None) -> None:
    """An 8-bit grey image (with alpha, where the format keeps it); row 0 is the top."""
    path = Path(path)
    fmt = path.suffix.lower().lstrip(".")
    grey = np.ascontiguousarray(grey, np.uint8)
    try:
        if fmt in NETPBM:
            height, width = grey.shape
            path.write_bytes(b"P5\n%d %d\n255\n" % (width, height) + grey.tobytes())
            return
        from PIL import Image

        if alpha is not None:
            rgba = np.dstack([grey, grey, grey, np.asarray(alpha, np.uint8)])
            Image.fromarray(rgba, "RGBA").save(path)
        else:
            Image.fromarray(grey, "L").save(path)
    except OSError as exc:
        raise ImageError(f"unable to write image '{path}': {exc.strerror or exc}") from None
    except (ImportError, KeyError, ValueError) as exc:
        raise ImageError(f"unable to write image '{path}' as {fmt}: {exc}") from None
