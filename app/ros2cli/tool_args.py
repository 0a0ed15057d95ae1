"""Words a program of the tf2 tutorials takes before ``--ros-args``.

Most catalog programs take no words, or whole numbers (``client 2 3``); the
tf2 tools take frame names and flags (``tf2_echo turtle2 turtle1``,
``static_transform_publisher --x 0 ... --frame-id world --child-frame-id
mystaticturtle``). The words go to the program as argv (never a shell) and
the program checks them itself; here they only have to look like what those
programs take: names, numbers and flags, no paths (view_frames' ``-o`` names
a file in its own folder). Nav2's ``map_saver_cli -f ~/maps/office`` is the one
that names a path: a value after ``-f`` may be a path under the home folder
(``~/...``) or under the working folder, never absolute and never through
``..``, so a browser cannot have it write anywhere else.
"""

from __future__ import annotations

import re

from app.ros.errors import Ros2Error

# catalog module -> the most words it takes
FREE_FORM: dict[str, int] = {
    "tf2_echo": 3,
    "tf2_monitor": 2,
    "static_transform_publisher": 24,
    "view_frames": 4,
    "static_turtle_tf2_broadcaster": 7,
    "map_saver_cli": 12,
}
_WORD = re.compile(r"^[A-Za-z0-9_.+\-]{1,100}$")
# module -> the flag whose value is a file path (where the program writes)
PATH_FLAGS = {"map_saver_cli": "-f"}
_PATH = re.compile(r"^(~/)?[A-Za-z0-9_.+\-][A-Za-z0-9_.+\-/]{0,199}$")


def check_words(module: str, words: list[str]) -> tuple[str, ...]:
    """The words unchanged, or a Ros2Error saying which one is not acceptable here."""
    limit = FREE_FORM[module]
    if len(words) > limit:
        raise Ros2Error(f"{module} takes at most {limit} words before --ros-args here")
    path_flag = PATH_FLAGS.get(module)
    for before, word in zip(["", *words], words, strict=False):
        if path_flag is not None and before == path_flag:
            _check_path(module, word)
            continue
        if not _WORD.match(word):
            raise Ros2Error(
                f"{module}: {word!r} is not a frame name, number or flag "
                "(letters, digits, _ . + - only here)"
            )
    return tuple(words)


def _check_path(module: str, word: str) -> None:
    """A Ros2Error unless ``word`` is a path under ~ or the working folder."""
    if not _PATH.match(word) or ".." in word.split("/"):
        raise Ros2Error(
            f"{module}: {word!r} is not a path this dashboard writes to "
            "(a name under ~/ or the working folder: letters, digits, _ . + - /, no ..)"
        )
