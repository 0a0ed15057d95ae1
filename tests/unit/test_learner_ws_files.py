"""The workspace file operations the page uses: confined, clear errors, nothing else touched."""

from __future__ import annotations

import pytest

from app.learner_ws import files
from app.learner_ws.folder import LearnerWorkspace, OutsideWorkspace


@pytest.fixture
def ws(tmp_path):
    (tmp_path / "outside.txt").write_text("keep\n")
    return LearnerWorkspace(tmp_path / "ros2_ws").ensure()


def test_create_edit_rename_delete(ws):
    files.create_folder(ws, "src/pkg/pkg")
    files.create_file(ws, "src/pkg/pkg/node.py")
    files.write_text(ws, "src/pkg/pkg/node.py", "print('hi')\n")
    assert files.read_text(ws, "~/ros2_ws/src/pkg/pkg/node.py") == "print('hi')\n"
    files.rename(ws, "src/pkg/pkg/node.py", "src/pkg/pkg/talker.py")
    assert files.tree(ws) == ["src/", "  pkg/", "    pkg/", "      talker.py"]
    files.delete(ws, "src/pkg")
    assert files.tree(ws) == ["src/"]


def test_colcon_folders_are_folded_in_the_tree(ws):
    (ws.root / "build" / "x").mkdir(parents=True)
    assert "build/ (colcon's; not listed)" in files.tree(ws)


def test_paths_outside_and_bad_requests(ws, tmp_path):
    for bad in ("../outside.txt", str(tmp_path / "outside.txt"), "~/elsewhere"):
        with pytest.raises(OutsideWorkspace):
            files.delete(ws, bad)
    (ws.root / "link").symlink_to(tmp_path)
    with pytest.raises(OutsideWorkspace):
        files.read_text(ws, "link/outside.txt")
    with pytest.raises(files.FileError, match="workspace itself"):
        files.delete(ws, ".")
    with pytest.raises(files.FileError, match="already exists"):
        files.create_folder(ws, "src")
    with pytest.raises(files.FileError, match="into itself"):
        files.rename(ws, "src", "src/inner")
    (ws.root / "blob.bin").write_bytes(b"\x00\x01")
    with pytest.raises(files.FileError, match="not a text file"):
        files.read_text(ws, "blob.bin")
    assert (tmp_path / "outside.txt").read_text() == "keep\n"
    assert (ws.root / "src").is_dir()
