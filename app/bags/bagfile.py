"""Opening a bag for reading: one clear line for anything that is not a readable bag."""

from __future__ import annotations

import sqlite3
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from rosbags.rosbag2 import Reader, ReaderError
from ruamel.yaml import YAMLError

from app.bags.errors import BagError

STORAGE_SUFFIXES = (".mcap", ".db3", ".mcap.zstd", ".db3.zstd")
# Everything a damaged or foreign file can make rosbags raise while opening it.
READ_ERRORS = (ReaderError, OSError, sqlite3.Error, YAMLError, ValueError, KeyError, TypeError)


def first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def bag_dir(path: Path) -> Path:
    """A bag is a folder; a storage file inside one names its folder."""
    if path.is_file() and path.name.endswith(STORAGE_SUFFIXES):
        return path.parent
    return path


def storage_files(folder: Path) -> list[Path]:
    return sorted(p for p in folder.iterdir() if p.name.endswith(STORAGE_SUFFIXES))


def check_bag_dir(path: Path) -> Path:
    """The bag folder, or BagError saying what is wrong with ``path``."""
    folder = bag_dir(path)
    if not folder.exists():
        raise BagError(f"no bag at {path}")
    if not folder.is_dir():
        raise BagError(f"{path} is not a bag: a bag is a folder with metadata.yaml and .mcap/.db3")
    if not (folder / "metadata.yaml").exists():
        if storage_files(folder):
            raise BagError(
                f"{folder} has no metadata.yaml: it is still being recorded, or its recording "
                f"was killed (then repair it with `ros2 bag reindex {folder}`)"
            )
        raise BagError(f"{folder} is not a bag: it has no metadata.yaml and no .mcap/.db3 file")
    return folder


@contextmanager
def open_bag(path: Path) -> Iterator[Reader]:
    """rosbags' Reader on a bag folder; damaged or foreign files become one BagError line."""
    folder = check_bag_dir(path)
    try:
        reader = Reader(folder)
        reader.open()
    except READ_ERRORS as exc:
        raise BagError(f"cannot read the bag {folder}: {first_line(exc)}") from None
    try:
        yield reader
    finally:
        try:
            reader.close()
        except READ_ERRORS:
            pass
