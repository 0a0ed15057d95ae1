"""The bridge's assets: the files a robot description names, for Foxglove's 3D panel.

A URDF names its meshes and textures as ``package://<package>/<path>``;
Foxglove asks the server for each one ("fetchAsset") as rviz asks ROS's
resource retriever. The file comes from that package's share folder, found in
the ament index as ``ros2 pkg prefix`` finds it (``AMENT_PREFIX_PATH``, else
this Python's prefix, where the classroom's packages are). Nothing else is
served: no ``file://`` or other scheme, no path that leaves the share folder
(``..`` or a link out of it), nothing over ``MAX_ASSET_BYTES``.

Called on the SDK's threads; it only reads files.
"""

from __future__ import annotations

import logging
import os
import sys
from pathlib import Path

log = logging.getLogger(__name__)

SCHEME = "package://"
MAX_ASSET_BYTES = 64 * 1024 * 1024  # a detailed mesh is a few megabytes


def _prefixes() -> list[Path]:
    text = os.environ.get("AMENT_PREFIX_PATH", "") or sys.prefix
    return [Path(p) for p in text.split(os.pathsep) if p]


def share_folder(package: str) -> Path | None:
    """``<prefix>/share/<package>`` of the first prefix that indexes ``package``."""
    if not package or "/" in package or package in (".", ".."):
        return None
    for prefix in _prefixes():
        if (prefix / "share" / "ament_index" / "resource_index" / "packages" / package).is_file():
            return prefix / "share" / package
    return None


def fetch_asset(uri: str) -> bytes | None:
    """The bytes of ``package://pkg/path``, or None (not found, or not ours to serve)."""
    if not uri.startswith(SCHEME):
        return None
    package, _, relative = uri[len(SCHEME) :].partition("/")
    share = share_folder(package)
    if share is None or not relative:
        return None
    try:
        root = share.resolve(strict=True)
        path = (root / relative).resolve(strict=True)
        if not path.is_relative_to(root) or not path.is_file():
            return None
        if path.stat().st_size > MAX_ASSET_BYTES:
            log.warning("foxglove: asset %s is over %d bytes: not sent", uri, MAX_ASSET_BYTES)
            return None
        return path.read_bytes()
    except OSError:  # gone, unreadable, a loop of links
        return None
