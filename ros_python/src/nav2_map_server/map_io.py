"""map_io: map files in, OccupancyGrid out, and back (Nav2 Jazzy's rules).

Loading (``load_map_from_yaml``): the YAML file names the image (a path
relative to the YAML's folder, or absolute), the ``resolution`` (m per
pixel), the ``origin`` ``[x, y, yaw]`` of the image's lower-left pixel in the
map frame, ``occupied_thresh`` and ``free_thresh``, ``negate`` (0/1 or
true/false) and optionally ``mode`` (trinary, the default; scale; raw). Each
pixel's grey level g (0..255) becomes an occupancy ``occ = 1 - g/255``
(``g/255`` when negated); in trinary and scale modes ``occ >=
occupied_thresh`` is 100, ``occ <= free_thresh`` is 0, and in between is -1
(trinary) or scaled to 1..99 (scale); a transparent pixel is -1. In raw mode
the grey level itself is the value (0..100, else -1). The image's top row is
the map's last row.

Saving (``save_map_to_file``): trinary writes free cells (<= free_thresh x
100) as 254, occupied (>= occupied_thresh x 100) as 0 and the rest as 205, in
a PGM, with a YAML whose thresholds are 0.65 and 0.196 (what those three grey
levels need to load back as they were); resolution and origin with three
decimals, as Nav2 Jazzy writes them.

Our additions, each a clear error where Nav2 would load nonsense: a
resolution that is not a positive number, an origin or a threshold that is
not a number, thresholds outside 0..1 or in the wrong order.
"""

from __future__ import annotations

import array
import math
import os
import time
from dataclasses import dataclass, field
from enum import IntEnum
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from nav2_util.occ_grid_values import OCC_GRID_FREE, OCC_GRID_OCCUPIED, OCC_GRID_UNKNOWN
from nav_msgs.msg import OccupancyGrid
from rclpy.logging import get_logger

from nav2_map_server.image_io import ImageError, read_image, writable, write_image
from nav2_map_server.map_mode import MapMode, map_mode_from_string, map_mode_to_string

BLESSED_FORMATS = ("bmp", "pgm", "png")
FALLBACK_FORMAT = "png"
TRINARY_OCCUPIED_THRESH = 0.65  # what the saved 0 / 205 / 254 pixels need to load back
TRINARY_FREE_THRESH = 0.196


class LoadMapStatus(IntEnum):
    LOAD_MAP_SUCCESS = 0
    MAP_DOES_NOT_EXIST = 1
    INVALID_MAP_METADATA = 2
    INVALID_MAP_DATA = 3


class MapYamlError(ValueError):
    """A map YAML file that cannot be used; the message names the tag and the reason."""


@dataclass
class LoadParameters:
    image_file_name: str = ""
    resolution: float = 0.0
    origin: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    free_thresh: float = 0.0
    occupied_thresh: float = 0.0
    mode: MapMode = MapMode.TRINARY
    negate: bool = False


@dataclass
class SaveParameters:
    map_file_name: str = ""
    image_format: str = ""
    free_thresh: float = 0.0  # 0: the default (0.25)
    occupied_thresh: float = 0.0  # 0: the default (0.65)
    mode: MapMode = MapMode.TRINARY


@dataclass
class LoadResult:
    status: LoadMapStatus
    map: OccupancyGrid | None = None
    reason: str = ""  # why it failed, as logged

    @property
    def ok(self) -> bool:
        return self.status == LoadMapStatus.LOAD_MAP_SUCCESS


_log = get_logger("map_io")


def expand_user_home_dir_if_needed(filename: str, home: str | None = None) -> str:
    """``~/maps/a.yaml`` -> ``$HOME/maps/a.yaml`` (only a leading ``~/``, as Nav2 does)."""
    home = os.environ.get("HOME", "") if home is None else home
    if not filename.startswith("~/") or not home:
        return filename
    return home + filename[1:]


def _get(doc: dict[str, Any], key: str, kind: str) -> Any:
    if key not in doc or doc[key] is None:
        raise MapYamlError(f"Failed to parse YAML tag '{key}' for reason: it is missing")
    value = doc[key]
    ok = {
        "str": isinstance(value, str),
        "float": isinstance(value, (int, float)) and not isinstance(value, bool),
        "list": isinstance(value, list),
    }[kind]
    if not ok:
        raise MapYamlError(
            f"Failed to parse YAML tag '{key}' for reason: bad conversion ({value!r} is not a "
            f"{ {'str': 'string', 'float': 'number', 'list': 'list'}[kind] })"
        )
    return value


def load_map_yaml(yaml_filename: str) -> LoadParameters:
    """The load parameters a map YAML file gives; MapYamlError (or OSError) says what is wrong."""
    path = Path(expand_user_home_dir_if_needed(yaml_filename))
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise MapYamlError(f"bad file: '{path}' does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise MapYamlError(f"bad file: '{path}' cannot be read ({exc})") from None
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or str(exc)
        raise MapYamlError(f"not valid YAML{where}: {problem}") from None
    if not isinstance(doc, dict):
        raise MapYamlError("the file does not hold a YAML map of tags (image: ..., ...)")
    params = LoadParameters()
    image = _get(doc, "image", "str")
    if not image:
        raise MapYamlError("The image tag was empty.")
    if not image.startswith("/"):
        image = str(path.parent / image)
    params.image_file_name = image
    params.resolution = float(_get(doc, "resolution", "float"))
    if not (math.isfinite(params.resolution) and params.resolution > 0.0):
        raise MapYamlError(
            f"value of the 'resolution' tag must be a positive number of metres per pixel, "
            f"not {doc['resolution']!r}"
        )
    origin = _get(doc, "origin", "list")
    if len(origin) != 3:
        raise MapYamlError(f"value of the 'origin' tag should have 3 elements, not {len(origin)}")
    if not all(
        isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in origin
    ):
        raise MapYamlError(f"value of the 'origin' tag must be 3 numbers [x, y, yaw]: {origin}")
    params.origin = [float(v) for v in origin]
    params.free_thresh = float(_get(doc, "free_thresh", "float"))
    params.occupied_thresh = float(_get(doc, "occupied_thresh", "float"))
    for key in ("free_thresh", "occupied_thresh"):
        value = getattr(params, key)
        if not (math.isfinite(value) and 0.0 <= value <= 1.0):
            raise MapYamlError(f"value of the '{key}' tag must be between 0.0 and 1.0: {value}")
    if params.free_thresh >= params.occupied_thresh:
        raise MapYamlError(
            f"free_thresh ({params.free_thresh}) must be smaller than occupied_thresh "
            f"({params.occupied_thresh})"
        )
    mode = doc.get("mode")
    if mode is None:
        params.mode = MapMode.TRINARY
    elif not isinstance(mode, str):
        raise MapYamlError(f"Failed to parse YAML tag 'mode' for reason: {mode!r} is not a name")
    else:
        params.mode = map_mode_from_string(mode)
    negate = doc.get("negate")
    if isinstance(negate, bool) or (isinstance(negate, int) and negate in (0, 1)):
        params.negate = bool(negate)
    else:
        raise MapYamlError(
            f"Failed to parse YAML tag 'negate' for reason: {negate!r} is not 0, 1, true or false"
        )
    for key in ("resolution", "origin", "free_thresh", "occupied_thresh", "mode", "negate"):
        value = getattr(params, key)
        shown = map_mode_to_string(value) if key == "mode" else value
        _log.debug(f"{key}: {shown}")
    return params


def load_map_from_file(params: LoadParameters) -> OccupancyGrid:
    """The OccupancyGrid of an image under these parameters (ImageError if unreadable)."""
    _log.info(f"Loading image_file: {params.image_file_name}")
    grey, alpha = read_image(params.image_file_name)
    height, width = grey.shape
    if params.mode in (MapMode.TRINARY, MapMode.SCALE):
        # float32 arithmetic, as Nav2's (a 205 pixel: 0.19607843 > 0.196, unknown)
        normalized = grey.astype(np.float32) / np.float32(255.0)
        if not params.negate:
            normalized = np.float32(1.0) - normalized
        occupied_thresh = np.float32(params.occupied_thresh)
        free_thresh = np.float32(params.free_thresh)
        result = np.full(grey.shape, OCC_GRID_UNKNOWN, np.int8)
        result[normalized >= occupied_thresh] = OCC_GRID_OCCUPIED
        result[normalized <= free_thresh] = OCC_GRID_FREE
        if params.mode == MapMode.SCALE:
            between = (normalized > free_thresh) & (normalized < occupied_thresh)
            scaled = (normalized - free_thresh) / (occupied_thresh - free_thresh) * 100.0
            result[between] = np.rint(scaled[between]).astype(np.int8)
        if alpha is not None:
            result[alpha < 255] = OCC_GRID_UNKNOWN
    else:  # raw: the grey level is the value
        result = np.where(grey <= OCC_GRID_OCCUPIED, grey, OCC_GRID_UNKNOWN).astype(np.int8)
    msg = OccupancyGrid()
    msg.info.width, msg.info.height = width, height
    msg.info.resolution = params.resolution
    x, y, yaw = params.origin
    msg.info.origin.position.x, msg.info.origin.position.y = x, y
    msg.info.origin.orientation.z = math.sin(yaw / 2.0)
    msg.info.origin.orientation.w = math.cos(yaw / 2.0)
    msg.data = array.array("b", np.ascontiguousarray(result[::-1]).tobytes())  # bottom row first
    now = time.time()
    stamp = msg.header.stamp
    stamp.sec, stamp.nanosec = int(now), int((now % 1.0) * 1e9)
    msg.info.map_load_time = stamp
    msg.header.frame_id = "map"
    _log.info(
        f"Read map {params.image_file_name}: {width} X {height} map @ {params.resolution} m/cell"
    )
    return msg


def load_map_from_yaml(yaml_file: str) -> LoadResult:
    """Load a map YAML and its image; the status says what went wrong (and it is logged)."""
    if not yaml_file:
        reason = "YAML file name is empty, can't load!"
        _log.error(reason)
        return LoadResult(LoadMapStatus.MAP_DOES_NOT_EXIST, reason=reason)
    _log.info(f"Loading yaml file: {yaml_file}")
    try:
        params = load_map_yaml(yaml_file)
    except (MapYamlError, ValueError) as exc:
        reason = f"Failed processing YAML file {yaml_file} for reason: {exc}"
        _log.error(reason)
        return LoadResult(LoadMapStatus.INVALID_MAP_METADATA, reason=reason)
    try:
        grid = load_map_from_file(params)
    except (ImageError, ValueError, MemoryError) as exc:
        reason = f"Failed to load image file {params.image_file_name} for reason: {exc}"
        _log.error(reason)
        return LoadResult(LoadMapStatus.INVALID_MAP_DATA, reason=reason)
    return LoadResult(LoadMapStatus.LOAD_MAP_SUCCESS, grid)


# ------------------------------------------------------------------ saving


def check_save_parameters(params: SaveParameters) -> None:
    """Fill in the defaults and check the rest (in place); ValueError when they cannot work."""
    if not params.map_file_name:
        params.map_file_name = f"map_{int(time.time())}"
        _log.warning(f"Map file unspecified. Map will be saved to {params.map_file_name} file")
    if params.occupied_thresh == 0.0:
        params.occupied_thresh = 0.65
        _log.warning(
            f"Occupied threshold unspecified. Setting it to default value: {params.occupied_thresh}"
        )
    if params.free_thresh == 0.0:
        params.free_thresh = 0.25
        _log.warning(
            f"Free threshold unspecified. Setting it to default value: {params.free_thresh}"
        )
    if params.occupied_thresh > 1.0:
        _log.error("Threshold_occupied must be 1.0 or less")
        raise ValueError("Incorrect thresholds")
    if params.free_thresh < 0.0:
        _log.error("Free threshold must be 0.0 or greater")
        raise ValueError("Incorrect thresholds")
    if params.occupied_thresh <= params.free_thresh:
        _log.error("Threshold_free must be smaller than threshold_occupied")
        raise ValueError("Incorrect thresholds")
    if not params.image_format:
        params.image_format = "png" if params.mode == MapMode.SCALE else "pgm"
        _log.warning(f"Image format unspecified. Setting it to: {params.image_format}")
    params.image_format = params.image_format.lower()
    if params.image_format not in BLESSED_FORMATS:
        blessed = ", ".join(f"'{f}'" for f in BLESSED_FORMATS)
        _log.warning(
            f"Requested image format '{params.image_format}' is not one of the recommended "
            f"formats: {blessed}"
        )
    if not writable(params.image_format):
        _log.warning(
            f"Format '{params.image_format}' is not writable. Using '{FALLBACK_FORMAT}' instead"
        )
        params.image_format = FALLBACK_FORMAT
    if params.mode == MapMode.SCALE and params.image_format in ("pgm", "jpg", "jpeg"):
        _log.warning(
            f"Map mode 'scale' requires transparency, but format '{params.image_format}' does "
            "not support it. Consider switching image format to 'png'."
        )


def _yaw(msg: OccupancyGrid) -> float:
    q = msg.info.origin.orientation
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def _g7(value: float) -> str:
    """A double as a C++ stream with precision 7 prints it (yaml-cpp's Precision(7))."""
    text = f"{value:.7g}"
    return "0" if text == "-0" else text


def map_yaml_text(image_name: str, msg: OccupancyGrid, params: SaveParameters) -> str:
    """The YAML Nav2 Jazzy's map_saver writes beside the image."""
    if params.mode == MapMode.TRINARY:
        occupied, free = _g7(TRINARY_OCCUPIED_THRESH), _g7(TRINARY_FREE_THRESH)
    else:
        occupied, free = f"{params.occupied_thresh:.3f}", f"{params.free_thresh:.3f}"
    origin = msg.info.origin.position
    return (
        f"image: {image_name}\n"
        f"mode: {map_mode_to_string(params.mode)}\n"
        f"resolution: {msg.info.resolution:.3f}\n"
        f"origin: [{origin.x:.3f}, {origin.y:.3f}, {_g7(_yaw(msg))}]\n"
        "negate: 0\n"
        f"occupied_thresh: {occupied}\n"
        f"free_thresh: {free}"
    )


def map_image(msg: OccupancyGrid, params: SaveParameters) -> tuple[np.ndarray, np.ndarray | None]:
    """(grey, alpha or None) pixels of a map, top row first, as map_saver draws them."""
    width, height = msg.info.width, msg.info.height
    cells = np.frombuffer(bytes(array.array("b", msg.data)), np.int8).astype(np.int16)
    if cells.size != width * height:
        raise ValueError(f"the map has {cells.size} cells for {width} x {height}")
    cells = cells.reshape(height, width)[::-1]
    unknown = (cells < 0) | (cells > 100)
    alpha = None
    if params.mode == MapMode.TRINARY:
        free_int = int(np.rint(params.free_thresh * 100.0))
        occupied_int = int(np.rint(params.occupied_thresh * 100.0))
        grey = np.full(cells.shape, 205, np.uint8)
        grey[cells >= occupied_int] = 0
        grey[cells <= free_int] = 254
        grey[unknown] = 205
    elif params.mode == MapMode.SCALE:
        grey = np.rint((100.0 - cells) / 100.0 * 255.0).clip(0, 255).astype(np.uint8)
        grey[unknown] = 128
        alpha = np.where(unknown, 0, 255).astype(np.uint8)
    else:
        grey = np.where(unknown, 255, cells).astype(np.uint8)
    return grey, alpha


def try_write_map_to_file(msg: OccupancyGrid, params: SaveParameters) -> None:
    """Write ``<map_file_name>.<image_format>`` and ``<map_file_name>.yaml`` (raises on error)."""
    _log.info(
        f"Received a {msg.info.width} X {msg.info.height} map @ {msg.info.resolution:g} m/pix"
    )
    image_file = f"{params.map_file_name}.{params.image_format}"
    grey, alpha = map_image(msg, params)
    _log.info(f"Writing map occupancy data to {image_file}")
    write_image(image_file, grey, alpha)
    yaml_file = f"{params.map_file_name}.yaml"
    image_name = image_file.replace("\\", "/").rsplit("/", 1)[-1]
    _log.info(f"Writing map metadata to {yaml_file}")
    try:
        Path(yaml_file).write_text(map_yaml_text(image_name, msg, params), encoding="utf-8")
    except OSError as exc:
        raise ValueError(f"unable to write '{yaml_file}': {exc.strerror or exc}") from None
    _log.info("Map saved")


def save_map_to_file(msg: OccupancyGrid, params: SaveParameters) -> bool:
    """Check the parameters, then write both files; False (and an error logged) if that fails."""
    local = SaveParameters(**vars(params))
    try:
        check_save_parameters(local)
        try_write_map_to_file(msg, local)
    except (ValueError, ImageError) as exc:
        _log.error(f"Failed to write map for reason: {exc}")
        return False
    return True
