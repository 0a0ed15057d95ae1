"""Words a program of the tf2 tutorials takes before ``--ros-args``.

Most catalog programs take no words, or whole numbers (``client 2 3``); the
tf2 tools take frame names and flags (``tf2_echo turtle2 turtle1``,
``static_transform_publisher --x 0 ... --frame-id world --child-frame-id
mystaticturtle``). The words go to the program as argv (never a shell) and
the program checks them itself; here they only have to look like what those
programs take: names, numbers and flags, no paths (view_frames' ``-o`` names
a file in its own folder).
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
}
_WORD = re.compile(r"^[A-Za-z0-9_.+\-]{1,100}$")


def check_words(module: str, words: list[str]) -> tuple[str, ...]:
    """The words unchanged, or a Ros2Error saying which one is not acceptable here."""
    limit = FREE_FORM[module]
    if len(words) > limit:
        raise Ros2Error(f"{module} takes at most {limit} words before --ros-args here")
    for word in words:
        if not _WORD.match(word):
            raise Ros2Error(
                f"{module}: {word!r} is not a frame name, number or flag "
                "(letters, digits, _ . + - only here)"
            )
    return tuple(words)
