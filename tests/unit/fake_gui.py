"""A stand-in for viser's GuiApi: enough for panels to build, be clicked and be read.

Panel state logic is tested without a browser or a server: a test builds a
panel on a ``FakeGui``, "clicks" with ``handle.click()`` / ``handle.set()``
(which run the callbacks as viser would, on the calling thread) and drives
the UI thread by hand with ``drain(ui)``.
"""

from __future__ import annotations

import time
from typing import Any

from app.ui.loop import UiLoop


class FakeHandle:
    def __init__(self, kind: str, label: str = "", value: Any = None, **props: Any) -> None:
        self.kind, self.label, self.value = kind, label, value
        self.options = tuple(props.pop("options", ()))
        self.disabled = props.pop("disabled", False)
        self.content = props.pop("content", "")
        self.visible = True
        self.removed = False
        self.props = props
        self._callbacks: list[Any] = []

    def on_click(self, callback: Any) -> Any:
        self._callbacks.append(callback)
        return callback

    on_update = on_click

    def click(self) -> None:
        """What viser does when the learner clicks: every callback, with an event."""
        for callback in self._callbacks:
            callback(object())

    def set(self, value: Any) -> None:
        """The learner changes the widget in the page."""
        self.value = value
        self.click()

    def remove(self) -> None:
        self.removed = True

    def __enter__(self) -> FakeHandle:
        return self

    def __exit__(self, *exc: object) -> None:
        return None


class FakeGui:
    def __init__(self) -> None:
        self.handles: list[FakeHandle] = []

    def _add(self, kind: str, label: str = "", value: Any = None, **props: Any) -> FakeHandle:
        handle = FakeHandle(kind, label, value, **props)
        self.handles.append(handle)
        return handle

    def add_markdown(self, content: str = "", **_: Any) -> FakeHandle:
        return self._add("markdown", content=content)

    def add_html(self, content: str = "", **_: Any) -> FakeHandle:
        return self._add("html", content=content)

    def add_button(self, label: str, **props: Any) -> FakeHandle:
        return self._add("button", label, False, disabled=props.get("disabled", False))

    def add_dropdown(self, label: str, options: Any, initial_value: Any = None, **_: Any):
        options = tuple(options)
        first = initial_value if initial_value is not None else options[0]
        return self._add("dropdown", label, first, options=options)

    def add_checkbox(self, label: str, initial_value: bool = False, **props: Any) -> FakeHandle:
        return self._add("checkbox", label, initial_value, disabled=props.get("disabled", False))

    def add_number(self, label: str, initial_value: float = 0, **props: Any) -> FakeHandle:
        return self._add("number", label, initial_value, disabled=props.get("disabled", False))

    def add_slider(self, label: str, low: float, high: float, step: float, value: float, **_: Any):
        return self._add("slider", label, value, low=low, high=high, step=step)

    def add_text(self, label: str, initial_value: str = "", **props: Any) -> FakeHandle:
        return self._add("text", label, initial_value, disabled=props.get("disabled", False))

    def add_progress_bar(self, value: float, **props: Any) -> FakeHandle:
        return self._add("progress", "", value, **props)

    def add_folder(self, label: str, **_: Any) -> FakeHandle:
        return self._add("folder", label)

    def find(self, kind: str, label: str) -> FakeHandle:
        found = [h for h in self.handles if h.kind == kind and h.label == label and not h.removed]
        assert found, f"no {kind} '{label}' (have: {[h.label for h in self.handles]})"
        return found[-1]

    def text(self) -> str:
        """Everything markdown and html widgets show now."""
        return "\n".join(h.content for h in self.handles if h.kind in ("markdown", "html"))


def drain(ui: UiLoop, until: Any = None, refresh: Any = None, timeout: float = 5.0) -> None:
    """Be the UI thread, as the dashboard's loop is: apply intents, then ``refresh()``.

    Stops when ``until()`` is true, or (without ``until``) once nothing more arrives.
    """
    deadline = time.monotonic() + timeout
    quiet_since = time.monotonic()
    while True:
        ui.wait(0.01)
        if ui.apply_pending():
            quiet_since = time.monotonic()
        if refresh is not None:
            refresh()
        if until is not None and until():
            return
        if until is None and time.monotonic() - quiet_since > 0.05:
            return
        assert time.monotonic() < deadline, "timed out driving the UI thread"
