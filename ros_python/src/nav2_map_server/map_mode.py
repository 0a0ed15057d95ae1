"""How an image's pixels become occupancy values: trinary, scale or raw."""

from __future__ import annotations

from enum import Enum


class MapMode(Enum):
    TRINARY = "trinary"  # occupied, free or unknown (100, 0, -1)
    SCALE = "scale"  # between the thresholds, a value from 1 to 99; transparent: unknown
    RAW = "raw"  # the pixel's grey value is the cell's value (0..100), else unknown


def map_mode_to_string(mode: MapMode) -> str:
    return mode.value


def map_mode_from_string(name: str) -> MapMode:
    """Case-insensitive; raises ValueError for anything but trinary, scale or raw."""
    try:
        return MapMode(name.lower())
    except ValueError:
        raise ValueError(f"map_mode_name: '{name}' is not trinary, scale or raw") from None
