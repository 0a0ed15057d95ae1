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


def test_the_editor_can_list_one_folder_at_a_time(ws):
    files.create_folder(ws, "src/pkg/pkg")
    files.create_file(ws, "src/pkg/setup.py")
    (ws.root / "build" / "pkg").mkdir(parents=True)
    (ws.root / ".hidden").mkdir()
    top = files.children(ws, "")
    assert [(e.path, e.folder, e.note) for e in top] == [
        ("build", True, "colcon's output"),
        ("src", True, ""),
    ]
    assert [e.path for e in files.children(ws, "~/ros2_ws/src/pkg")] == [
        "src/pkg/pkg",
        "src/pkg/setup.py",
    ]
    assert files.relative(ws, "~/ros2_ws/src/pkg/../pkg/setup.py") == "src/pkg/setup.py"
    many = ws.root / "many"
    many.mkdir()
    for i in range(12):
        (many / f"f{i:02d}").write_text("")
    listed = files.children(ws, "many", limit=10)
    assert len(listed) == 11 and listed[-1].note == "... and 2 more"
    with pytest.raises(files.FileError, match="not a folder"):
        files.children(ws, "src/pkg/setup.py")


def test_saves_keep_the_mode_and_leave_no_temporary_file(ws):
    script = ws.src / "run.sh"
    files.write_text(ws, "src/run.sh", "#!/bin/sh\n")
    assert script.stat().st_mode & 0o777 == 0o644
    script.chmod(0o755)
    files.write_text(ws, "src/run.sh", "#!/bin/sh\necho hi\n")
    assert script.stat().st_mode & 0o777 == 0o755
    assert [p.name for p in ws.src.iterdir()] == ["run.sh"]


def test_a_folder_swapped_for_a_link_after_the_check_is_caught(ws, tmp_path):
    """confine() resolved the path; a link swapped in before the open is still refused."""
    outside = tmp_path / "outside_dir"
    outside.mkdir()
    (outside / "secret.txt").write_text("not yours\n")
    (ws.root / "build").mkdir()
    (ws.root / "build" / "swap").symlink_to(outside)
    swapped = ws.root / "build" / "swap" / "secret.txt"
    with pytest.raises(OutsideWorkspace, match="a link changed under it"):
        files.write_atomically(ws, swapped, "pwned\n")  # the path after its check
    assert (outside / "secret.txt").read_text() == "not yours\n"
    assert sorted(p.name for p in outside.iterdir()) == ["secret.txt"]
    with pytest.raises(OutsideWorkspace):
        files.read_text(ws, "build/swap/secret.txt")
