"""What our colcon extension adds to ``--cmake-args``, and what the typed arguments keep."""

from __future__ import annotations

import sys

from app.learner_ws.colcon_extension import TOOLCHAIN, with_defaults


def test_ours_follow_what_was_typed():
    assert with_defaults(None) == [
        f"-DCMAKE_TOOLCHAIN_FILE={TOOLCHAIN}",
        f"-DPython3_EXECUTABLE={sys.executable}",
        f"-DCLASSROOM_UNDERLAY={sys.prefix}",
        "-Wno-deprecated",
    ]


def test_a_typed_variable_or_warning_switch_wins():
    typed = ["-D", "Python3_EXECUTABLE=/usr/bin/python3", "-Wdeprecated"]
    args = with_defaults(typed)
    assert args[:3] == typed
    assert not [a for a in args[3:] if "Python3_EXECUTABLE" in a or "deprecated" in a], args
    assert f"-DCMAKE_TOOLCHAIN_FILE={TOOLCHAIN}" in args
