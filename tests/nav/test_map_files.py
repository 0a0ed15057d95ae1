"""Map files as Nav2 writes and reads them: nav2_map_server.map_io, without ROS traffic.

The hand-written files follow the format as Nav2's map_server documents it
(a PGM image and a YAML beside it): what the real map_saver leaves on disk
must load here, and what we write must be what it writes.
"""

from __future__ import annotations

import array
import math
from pathlib import Path

import numpy as np
import pytest
from nav2_map_server.image_io import read_image
from nav2_map_server.map_io import (
    LoadMapStatus,
    SaveParameters,
    load_map_from_yaml,
    map_yaml_text,
    save_map_to_file,
)
from nav2_map_server.map_mode import MapMode
from nav_msgs.msg import OccupancyGrid

# A 4 x 3 map as the real map_saver writes it (trinary): the image's top row is the map's
# last row; 254 free, 0 occupied, 205 unknown.
PIXELS = [
    [0, 0, 0, 0],
    [254, 254, 205, 0],
    [254, 254, 254, 0],
]
EXPECTED_DATA = [0, 0, 0, 100, 0, 0, -1, 100, 100, 100, 100, 100]  # bottom row first
NAV2_YAML = """image: hand.pgm
mode: trinary
resolution: 0.050
origin: [-1.250, 2.500, 0]
negate: 0
occupied_thresh: 0.65
free_thresh: 0.196"""


def write_hand_made(folder: Path, yaml_text: str = NAV2_YAML, plain: bool = False) -> Path:
    """A PGM as netpbm defines it (header, then the grey levels), and its YAML."""
    if plain:  # P2: the numbers as text, with a comment line as GIMP writes one
        body = "\n".join(" ".join(str(v) for v in row) for row in PIXELS)
        (folder / "hand.pgm").write_text(f"P2\n# made by hand\n4 3\n255\n{body}\n")
    else:
        (folder / "hand.pgm").write_bytes(b"P5\n4 3\n255\n" + bytes(sum(PIXELS, [])))
    path = folder / "hand.yaml"
    path.write_text(yaml_text)
    return path


def grid(width: int, height: int, data: list[int], origin=(0.0, 0.0), yaw=0.0) -> OccupancyGrid:
    msg = OccupancyGrid()
    msg.info.width, msg.info.height, msg.info.resolution = width, height, 0.05
    msg.info.origin.position.x, msg.info.origin.position.y = origin
    msg.info.origin.orientation.z, msg.info.origin.orientation.w = (
        math.sin(yaw / 2),
        math.cos(yaw / 2),
    )
    msg.data = array.array("b", data)
    return msg


@pytest.mark.parametrize("plain", [False, True], ids=["P5", "P2"])
def test_a_map_the_real_map_saver_wrote_loads(tmp_path, plain):
    result = load_map_from_yaml(str(write_hand_made(tmp_path, plain=plain)))
    assert result.status == LoadMapStatus.LOAD_MAP_SUCCESS, result.reason
    msg = result.map
    assert (msg.info.width, msg.info.height) == (4, 3)
    assert msg.info.resolution == pytest.approx(0.05)
    assert (msg.info.origin.position.x, msg.info.origin.position.y) == (-1.25, 2.5)
    assert msg.info.origin.orientation.w == 1.0
    assert msg.header.frame_id == "map"
    assert list(msg.data) == EXPECTED_DATA


def test_the_older_yaml_forms_load_too(tmp_path):
    """No mode (trinary), negate as a bool, ROS 1's free_thresh 0.196, an absolute image path,
    a yaw in the origin."""
    image = tmp_path / "hand.pgm"
    text = (
        f"image: {image}\nresolution: 0.1\norigin: [1.0, -2.0, 1.5707963]\n"
        "negate: false\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    path = write_hand_made(tmp_path, text)
    result = load_map_from_yaml(str(path))
    assert result.ok, result.reason
    assert list(result.map.data) == EXPECTED_DATA
    assert result.map.info.origin.orientation.z == pytest.approx(math.sin(math.pi / 4))


def test_negate_swaps_black_and_white(tmp_path):
    path = write_hand_made(tmp_path, NAV2_YAML.replace("negate: 0", "negate: 1"))
    data = list(load_map_from_yaml(str(path)).map.data)
    # occ = grey / 255: white (254) and the grey 205 (0.80) are occupied now, black is free
    assert data == [0 if v == 100 else 100 for v in EXPECTED_DATA]


def test_saving_writes_what_nav2_jazzy_writes(tmp_path):
    # 0 free, 100 occupied, -1 unknown, 30 (between the thresholds) unknown in trinary
    msg = grid(3, 2, [0, 100, -1, 30, 0, 100], origin=(-10.0, -7.5))
    base = tmp_path / "office"
    assert save_map_to_file(msg, SaveParameters(map_file_name=str(base)))
    assert (tmp_path / "office.yaml").read_text() == (
        "image: office.pgm\nmode: trinary\nresolution: 0.050\norigin: [-10.000, -7.500, 0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196"
    )
    raw = (tmp_path / "office.pgm").read_bytes()
    assert raw == b"P5\n3 2\n255\n" + bytes([205, 254, 0, 254, 0, 205])  # top row first


def test_a_saved_map_loads_back_as_it_was(tmp_path):
    rng = np.random.default_rng(3)
    data = rng.choice([-1, 0, 100], size=40 * 30).tolist()
    msg = grid(40, 30, data, origin=(-1.05, 3.2), yaw=0.5)
    assert save_map_to_file(msg, SaveParameters(map_file_name=str(tmp_path / "m")))
    back = load_map_from_yaml(str(tmp_path / "m.yaml")).map
    assert list(back.data) == data
    assert (back.info.width, back.info.height) == (40, 30)
    assert back.info.origin.position.x == pytest.approx(-1.05)
    assert back.info.origin.position.y == pytest.approx(3.2)
    yaw = 2 * math.atan2(back.info.origin.orientation.z, back.info.origin.orientation.w)
    assert yaw == pytest.approx(0.5, abs=1e-6)


@pytest.mark.parametrize("mode", [MapMode.SCALE, MapMode.RAW])
def test_scale_and_raw_maps_round_trip(tmp_path, mode):
    data = [-1, 0, 12, 50, 87, 100]
    msg = grid(3, 2, data)
    params = SaveParameters(map_file_name=str(tmp_path / "m"), mode=mode)
    assert save_map_to_file(msg, params)
    suffix = "png" if mode == MapMode.SCALE else "pgm"
    assert (tmp_path / f"m.{suffix}").is_file()
    back = list(load_map_from_yaml(str(tmp_path / "m.yaml")).map.data)
    if mode == MapMode.RAW:
        assert back == data
    else:  # scale: free and occupied exact, the middle rescaled between the thresholds
        assert back[0] == -1 and back[1] == 0 and back[5] == 100
        assert back[2] < back[3] < back[4]


def test_a_png_map_loads(tmp_path):
    from PIL import Image

    Image.fromarray(np.array(PIXELS, np.uint8), "L").save(tmp_path / "hand.png")
    path = tmp_path / "hand.yaml"
    path.write_text(NAV2_YAML.replace("hand.pgm", "hand.png"))
    assert list(load_map_from_yaml(str(path)).map.data) == EXPECTED_DATA


def test_the_image_reader_reads_16_bit_and_colour_netpbm(tmp_path):
    (tmp_path / "a.pgm").write_bytes(b"P5 2 1 65535\n" + bytes([0, 0, 255, 255]))
    grey, alpha = read_image(tmp_path / "a.pgm")
    assert grey.tolist() == [[0, 255]] and alpha is None
    (tmp_path / "b.ppm").write_bytes(b"P6\n2 1\n255\n" + bytes([255, 0, 0, 0, 0, 255]))
    assert read_image(tmp_path / "b.ppm")[0].tolist() == [[76, 29]]


BAD = {
    "not yaml at all": ("image: [hand.pgm\nresolution: 0.05", "not valid YAML"),
    "no resolution": (NAV2_YAML.replace("resolution: 0.050\n", ""), "'resolution'"),
    "zero resolution": (NAV2_YAML.replace("0.050", "0"), "positive number"),
    "negative resolution": (NAV2_YAML.replace("0.050", "-0.05"), "positive number"),
    "resolution as text": (NAV2_YAML.replace("0.050", "fine"), "'resolution'"),
    "two origin values": (NAV2_YAML.replace("[-1.250, 2.500, 0]", "[1, 2]"), "3 elements"),
    "an unknown mode": (NAV2_YAML.replace("trinary", "colourful"), "colourful"),
    "thresholds swapped": (
        NAV2_YAML.replace("0.65", "0.1").replace("0.196", "0.9"),
        "must be smaller",
    ),
    "empty image": (NAV2_YAML.replace("hand.pgm", "''"), "image tag was empty"),
    "a list, not a map": ("- image: hand.pgm", "YAML map"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_malformed_yaml_is_invalid_metadata_with_the_reason(tmp_path, case):
    text, reason = BAD[case]
    path = write_hand_made(tmp_path, text)
    result = load_map_from_yaml(str(path))
    assert result.status == LoadMapStatus.INVALID_MAP_METADATA
    assert result.map is None and reason in result.reason, result.reason


def test_a_missing_or_broken_image_is_invalid_map_data(tmp_path):
    path = write_hand_made(tmp_path)
    (tmp_path / "hand.pgm").unlink()
    result = load_map_from_yaml(str(path))
    assert result.status == LoadMapStatus.INVALID_MAP_DATA
    assert "hand.pgm" in result.reason and "no such file" in result.reason
    (tmp_path / "hand.pgm").write_bytes(b"P5\n4 3\n255\n\x00\x01")  # two of twelve pixels
    result = load_map_from_yaml(str(path))
    assert result.status == LoadMapStatus.INVALID_MAP_DATA and "short" in result.reason
    (tmp_path / "hand.pgm").write_bytes(b"GIF89a not an image at all")
    assert load_map_from_yaml(str(path)).status == LoadMapStatus.INVALID_MAP_DATA


def test_no_file_name_and_a_missing_file(tmp_path):
    assert load_map_from_yaml("").status == LoadMapStatus.MAP_DOES_NOT_EXIST
    missing = load_map_from_yaml(str(tmp_path / "nowhere.yaml"))
    assert missing.status == LoadMapStatus.INVALID_MAP_METADATA  # as Nav2 reports it
    assert "does not exist" in missing.reason


def test_bad_save_parameters_are_refused(tmp_path):
    msg = grid(1, 1, [0])
    for params in (
        SaveParameters(map_file_name=str(tmp_path / "a"), occupied_thresh=1.5),
        SaveParameters(map_file_name=str(tmp_path / "b"), free_thresh=0.7, occupied_thresh=0.6),
    ):
        assert not save_map_to_file(msg, params)
    assert not list(tmp_path.iterdir())
    assert not save_map_to_file(msg, SaveParameters(map_file_name=str(tmp_path / "no/dir/m")))


def test_the_yaml_of_a_non_trinary_map_keeps_its_thresholds():
    msg = grid(1, 1, [0], origin=(0.123456, -4.0))
    params = SaveParameters(mode=MapMode.SCALE, free_thresh=0.2, occupied_thresh=0.7)
    text = map_yaml_text("x.png", msg, params)
    assert "origin: [0.123, -4.000, 0]" in text
    assert "occupied_thresh: 0.700\nfree_thresh: 0.200" in text
