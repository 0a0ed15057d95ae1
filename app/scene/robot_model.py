"""A robot description (URDF text) as meshes per link, ready to hang under TF frames.

rviz's RobotModel draws each link's visuals at the link's TF frame; the URDF
supplies only shapes, colours and each visual's offset in its link. We check
the description with our robot_state_publisher's parser first (it refuses,
in one line, what urdfdom refuses: broken XML, an unknown parent link, a
loop, NaN) and then let yourdfpy (the library viser's URDF helper is built
on) turn boxes, cylinders, spheres and mesh files into trimesh meshes with
the URDF's material colours. Mesh files are read only from ``package://``
packages on the ament index or absolute paths, only with a mesh extension
and under a size bound.
"""

from __future__ import annotations

import io
import logging
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from robot_state_publisher.urdf_tree import UrdfError, parse_urdf

if TYPE_CHECKING:  # imported when a robot is first drawn: trimesh brings scipy (1-2 s)
    import trimesh

MAX_DESCRIPTION_BYTES = 4 * 1024 * 1024
MAX_MESH_BYTES = 50 * 1024 * 1024
MESH_SUFFIXES = (".stl", ".dae", ".obj", ".ply", ".glb", ".gltf", ".off")
MISSING = "/nonexistent/mesh-not-allowed"


@dataclass(frozen=True)
class LinkVisual:
    link: str
    mesh: trimesh.Trimesh  # already placed by the visual's origin, in the link frame


@dataclass(frozen=True)
class SliderJoint:
    """A joint a slider may set, as joint_state_publisher_gui offers it (continuous: +-pi)."""

    name: str
    lower: float
    upper: float


@dataclass(frozen=True)
class RobotDrawing:
    name: str
    links: tuple[str, ...]
    visuals: tuple[LinkVisual, ...]
    warnings: tuple[str, ...]
    joints: tuple[SliderJoint, ...] = ()


def resolve_mesh(fname: str) -> str:
    """A readable mesh file for a URDF mesh ``fname``, or a path that does not exist."""
    filename = fname
    path: Path | None = None
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://") :].partition("/")
        try:
            from ament_index_python.packages import get_package_share_directory

            path = Path(get_package_share_directory(package)) / rest
        except Exception:  # not on the ament index: the mesh is missing, not an error
            return MISSING
    elif filename.startswith("file://"):
        path = Path(filename[len("file://") :])
    elif os.path.isabs(filename):
        path = Path(filename)
    if path is None or path.suffix.lower() not in MESH_SUFFIXES:
        return MISSING
    try:
        if not path.is_file() or path.stat().st_size > MAX_MESH_BYTES:
            return MISSING
    except OSError:
        return MISSING
    return str(path)


def build_drawing(text: str) -> RobotDrawing:
    """Meshes per link of a URDF; raises UrdfError with one line if it cannot be drawn."""
    size = len(text.encode("utf-8", "replace"))
    if size > MAX_DESCRIPTION_BYTES:
        raise UrdfError(
            f"robot_description is {size / 1e6:.1f} MB; the 3D view draws descriptions of up "
            f"to {MAX_DESCRIPTION_BYTES / 1e6:.0f} MB"
        )
    model = parse_urdf(text)
    import trimesh
    import yourdfpy

    warnings: list[str] = []
    handler = _CollectingHandler()
    logger = logging.getLogger("yourdfpy")
    logger.addHandler(handler)
    try:
        urdf = yourdfpy.URDF.load(
            io.BytesIO(text.encode("utf-8")),
            build_scene_graph=True,
            load_meshes=True,
            filename_handler=resolve_mesh,
        )
    except Exception as exc:  # yourdfpy raises many kinds; the learner needs one line
        raise UrdfError(f"cannot build the robot's geometry: {exc}") from None
    finally:
        logger.removeHandler(handler)
    warnings.extend(handler.lines)
    visuals: list[LinkVisual] = []
    scene = urdf.scene
    if scene is not None:
        parents = scene.graph.transforms.parents
        for geometry_name, mesh in scene.geometry.items():
            if not isinstance(mesh, trimesh.Trimesh):
                continue
            link = parents.get(geometry_name)
            if link not in model.links:
                continue
            offset = urdf.get_transform(geometry_name, link)
            if not np.all(np.isfinite(offset)):
                warnings.append(f"a visual of link [{link}] has a non-finite origin; not drawn")
                continue
            placed = mesh.copy()
            placed.apply_transform(offset)
            visuals.append(LinkVisual(link, placed))
    joints = tuple(
        SliderJoint(j.name, *_slider_range(j.lower, j.upper))
        for j in model.movable_joints()
        if j.mimic is None
    )
    return RobotDrawing(model.name, model.links, tuple(visuals), tuple(warnings), joints)


def _slider_range(lower: float | None, upper: float | None) -> tuple[float, float]:
    if lower is None or upper is None or not lower < upper:
        return (-math.pi, math.pi)
    return (lower, upper)


class _CollectingHandler(logging.Handler):
    """yourdfpy's warnings (a mesh it could not find) become lines for the panel."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        message = record.getMessage()
        if MISSING in message:
            message = "a mesh file could not be found or is not allowed"
        if message not in self.lines:
            self.lines.append(message)
