"""Write an ament prefix (files under ``lib/``, ``share/``) once, atomically.

Several processes may ask for the same prefix at the same moment (the
dashboard, a Console verb, a terminal): each writes into its own staging
folder and renames it into place; the first rename wins and the others drop
theirs, since the content is the same (the folder name is its hash).
Everything is world-readable, programs under ``lib/`` executable: contained
learner code runs as another user and must find them.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Mapping
from pathlib import Path

COMPLETE_MARKER = ".complete"


def write_prefix(prefix: Path, files: Mapping[str, str]) -> Path:
    """``prefix`` holding ``files`` (relative path -> text), written unless already complete."""
    if (prefix / COMPLETE_MARKER).is_file():
        return prefix
    prefix.parent.mkdir(parents=True, exist_ok=True)
    prefix.parent.chmod(0o755)  # a strict umask would hide it from contained learner code
    staging = Path(tempfile.mkdtemp(prefix=".staging-", dir=prefix.parent))
    try:
        for relative, text in files.items():
            path = staging / relative
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text, encoding="utf-8")
            path.chmod(0o755 if relative.startswith("lib/") else 0o644)
        (staging / COMPLETE_MARKER).write_text("", encoding="utf-8")
        for folder, _dirs, _names in os.walk(staging):
            os.chmod(folder, 0o755)
        try:
            staging.rename(prefix)
        except OSError:  # another process wrote the same prefix first: theirs is the same
            shutil.rmtree(staging, ignore_errors=True)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return prefix
