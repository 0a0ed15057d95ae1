"""The LTI service's state files (launches, the outbox, a classroom's seats), written whole.

A draft beside the file, flushed to disk, then renamed over it, and the folder synced so
that the rename itself survives a power cut: a reader (or a restarted service) finds the
old file or the new one, never half of one.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path


def save_json(path: Path, document: Mapping[str, object]) -> None:
    """Replace ``path`` with ``document`` as JSON, atomically; raises OSError."""
    draft = path.with_name(f".{path.name}.tmp")
    with open(draft, "w", encoding="utf-8") as out:
        json.dump(document, out, indent=1)
        out.flush()
        os.fsync(out.fileno())
    os.replace(draft, path)
    directory = os.open(path.parent, os.O_RDONLY)
    try:
        os.fsync(directory)
    finally:
        os.close(directory)
