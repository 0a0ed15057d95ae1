"""The Console tab's "Workspace files" folder: the learner's ~/ros2_ws as a tree, and edits to it.

What a file manager and a plain editor give a learner following the
tutorials: create, rename and delete files and folders, open a text file
(setup.py, package.xml, a node), edit it and save it. Paths are relative to
the workspace (``src/my_package/setup.py``) and confined to it
(app.learner_ws.files). This is viser's own text field, one file at a
time; the code window's editor (Files, beside its tabs) opens the same files
with completion, lint marks and Format, through the same confinement.
"""

from __future__ import annotations

import viser

from app.learner_ws import files, folder
from app.ros.errors import Ros2Error
from app.ui import MarkdownView, code_block
from app.ui.loop import UiLoop


class WorkspaceFiles:
    """A folder of widgets; every click is an intent run on the UI thread."""

    def __init__(self, gui: viser.GuiApi, ui: UiLoop) -> None:
        self._ui = ui
        with gui.add_folder("Workspace files (~/ros2_ws)", expand_by_default=False):
            gui.add_markdown(
                "Create, rename and delete here. To edit with completion and lint marks, "
                "open a file from **Files** in the code window (Exercise tab → Open my code)."
            )
            self._tree = MarkdownView(gui, "")
            self._path = gui.add_text("Path", "src/", hint="relative to ~/ros2_ws")
            self._new_name = gui.add_text("Rename to", "", hint="the new path, for Rename")
            buttons = gui.add_button_group("File", ("Open", "New file", "New folder"))
            more = gui.add_button_group("Change", ("Rename", "Delete", "Refresh"))
            self._confirm = gui.add_checkbox("Yes, delete it", False)
            self._text = gui.add_text("Text", "", multiline=True)
            self._save = gui.add_button("Save", icon=viser.Icon.DEVICE_FLOPPY)
            self._status = MarkdownView(gui, "")
        self._open: str | None = None
        buttons.on_click(lambda event: ui.post(lambda: self._file_action(event.target.value)))
        more.on_click(lambda event: ui.post(lambda: self._file_action(event.target.value)))
        self._save.on_click(ui.callback(self._save_text))
        self.refresh()

    def _file_action(self, action: str) -> None:
        ws = folder.current()
        if ws is None:
            self._say("no workspace here (the dashboard sets one up when it starts)")
            return
        path = self._path.value.strip()
        try:
            if action == "Open":
                self._text.value = files.read_text(ws, path)  # type: ignore[misc]
                self._open = path
                self._say(f"opened {path}: edit below, then Save")
            elif action == "New file":
                files.create_file(ws, path)
                self._say(f"created {path}")
            elif action == "New folder":
                files.create_folder(ws, path)
                self._say(f"created {path}/")
            elif action == "Rename":
                files.rename(ws, path, self._new_name.value)
                self._say(f"renamed {path} to {self._new_name.value.strip()}")
            elif action == "Delete":
                if not self._confirm.value:
                    self._say(f"tick 'Yes, delete it' first: {path} would be gone for good")
                    return
                files.delete(ws, path)
                self._confirm.value = False  # type: ignore[misc]
                self._say(f"deleted {path}")
        except (Ros2Error, OSError) as exc:
            self._say(f"error: {exc}")
        self.refresh()

    def _save_text(self) -> None:
        ws = folder.current()
        if ws is None or self._open is None:
            self._say("open a file first")
            return
        try:
            files.write_text(ws, self._open, self._text.value)
            self._say(f"saved {self._open}")
        except (Ros2Error, OSError) as exc:
            self._say(f"error: {exc}")
        self.refresh()

    def _say(self, text: str) -> None:
        self._status.show(text)

    def refresh(self) -> None:
        ws = folder.current()
        lines = files.tree(ws) if ws is not None else []
        self._tree.show(code_block(lines, "(empty: `ros2 pkg create ...` in the Console)"))
