"""Check ``map_file``: a saved map's YAML file loads as Nav2's map_server loads it.

``path`` is the ``.yaml`` file map_saver_cli wrote (``~`` is the home
folder, as in a terminal). It is read with our nav2_map_server's loader, so
a map that passes here is one Nav2's map_server (ours or the real one) can
serve; the result names its size and how much of it is known.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

from nav2_map_server.map_io import load_map_from_yaml

from app.lessons.registry import FAIL, PASS, CheckResult, register_check

if TYPE_CHECKING:
    from app.lessons.runtime import LessonRuntime
    from app.lessons.schema import Spec

_read: dict[str, tuple[float, CheckResult]] = {}  # path -> (modification time, its result)


@register_check(
    "map_file",
    required="path",
    words="the map's YAML file (and the image it names) exists and loads as Nav2's map_server "
    "loads it",
)
def evaluate(rt: LessonRuntime, c: Spec) -> CheckResult:
    path = Path(os.path.expanduser(str(c["path"])))
    try:
        changed = path.stat().st_mtime
    except OSError:
        return CheckResult(FAIL, f"{c['path']} does not exist yet")
    cached = _read.get(str(path))
    if cached is not None and cached[0] == changed:
        return cached[1]
    loaded = load_map_from_yaml(str(path))
    if not loaded.ok or loaded.map is None:
        result = CheckResult(FAIL, f"{c['path']} does not load: {loaded.reason}")
    else:
        info = loaded.map.info
        known = sum(1 for v in loaded.map.data if v >= 0)
        result = CheckResult(
            PASS,
            f"{c['path']} loads: {info.width} x {info.height} cells of {info.resolution:g} m, "
            f"{100.0 * known / max(1, info.width * info.height):.0f} % known",
        )
    _read[str(path)] = (changed, result)
    return result
