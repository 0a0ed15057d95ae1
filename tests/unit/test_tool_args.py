"""The words the browser's `ros2 run` passes to a program that takes words (tool_args)."""

from __future__ import annotations

import pytest

from app.ros.errors import Ros2Error
from app.ros2cli.tool_args import check_words


def test_map_saver_cli_takes_a_path_under_home_or_the_working_folder():
    assert check_words("map_saver_cli", ["-f", "~/maps/office"]) == ("-f", "~/maps/office")
    words = ["-t", "map", "-f", "maps/office", "--occ", "0.65", "--mode", "trinary"]
    assert check_words("map_saver_cli", words) == tuple(words)


@pytest.mark.parametrize(
    "path", ["/etc/passwd", "~/../etc/x", "maps/../../x", "~root/x", "a b", "~/$(id)"]
)
def test_map_saver_cli_refuses_a_path_elsewhere(path):
    with pytest.raises(Ros2Error, match="not a path this dashboard writes to"):
        check_words("map_saver_cli", ["-f", path])


def test_a_path_is_only_taken_after_its_flag():
    with pytest.raises(Ros2Error, match="not a frame name"):
        check_words("map_saver_cli", ["maps/office"])
    with pytest.raises(Ros2Error, match="not a frame name"):  # tf2 tools take no paths at all
        check_words("tf2_echo", ["-f", "~/x"])


def test_too_many_words_are_refused():
    with pytest.raises(Ros2Error, match="at most 12 words"):
        check_words("map_saver_cli", ["-f", "m"] * 7)
