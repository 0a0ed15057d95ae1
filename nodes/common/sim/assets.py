"""Where worlds and robots live, and loading a world with a reason when it fails.

Worlds and robots are files, so a teacher adds one without code:

- ``nodes/worlds/<name>/world.xml``: an MJCF world (walls, objects, lights) that
  places robots with ``<asset><model file="../../robots/<robot>/robot.xml"/></asset>``
  and ``<attach model=... body=... prefix=""/>``;
- ``nodes/robots/<robot>/robot.xml`` (MJCF, for the physics) and ``robot.urdf``
  (the same robot for robot_state_publisher and the 3D view).

They sit inside the ``nodes`` package, next to the node that loads them, so an
installed copy of the project carries them too.
"""

from __future__ import annotations

import re
from pathlib import Path

import mujoco

NODES_DIR = Path(__file__).resolve().parents[2]
WORLDS_DIR = NODES_DIR / "worlds"
ROBOTS_DIR = NODES_DIR / "robots"
_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_-]*$")


class WorldError(ValueError):
    """A world that cannot be loaded; the message says which file and why."""


def world_names() -> list[str]:
    """The worlds a teacher has put under nodes/worlds/ (folders with a world.xml)."""
    return sorted(p.parent.name for p in WORLDS_DIR.glob("*/world.xml"))


def world_path(world: str) -> Path:
    """``room`` -> nodes/worlds/room/world.xml; a path ending in .xml is taken as given."""
    if world.endswith(".xml"):
        path = Path(world).expanduser()
    elif _NAME.match(world):
        path = WORLDS_DIR / world / "world.xml"
    else:
        raise WorldError(f"world {world!r} is neither a world name nor a path to an .xml file")
    if not path.is_file():
        known = ", ".join(world_names()) or "none"
        raise WorldError(f"world file {path} does not exist (worlds under nodes/worlds: {known})")
    return path


def robot_file(robot: str, kind: str = "urdf") -> Path:
    """nodes/robots/<robot>/robot.<kind>: the URDF (or MJCF) of a robot."""
    return ROBOTS_DIR / robot / f"robot.{kind}"


def _quiet_warning(_text: str) -> None:
    """MuJoCo warns on every ``attach`` with an empty prefix; our names need no prefix."""


def load_world(world: str) -> mujoco.MjModel:
    """Compile a world; a parse or compile error becomes a WorldError naming the file."""
    path = world_path(world)
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(_quiet_warning)
    try:
        return mujoco.MjModel.from_xml_path(str(path))
    except ValueError as exc:  # MuJoCo raises ValueError with the parser's message
        reason = " ".join(str(exc).split())
        raise WorldError(f"world file {path} does not load: {reason}") from None
    finally:
        mujoco.set_mju_user_warning(previous)
