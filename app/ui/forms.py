"""Forms generated from message types: a widget per field, and a slot that holds one.

Used by the Services, Actions and Topics panels (requests, goals, messages).
Built and read on the UI thread only (see the threading model in app.ui).
"""

from __future__ import annotations

from collections.abc import Callable

import viser

from app.ros.convert import ConversionError, fill_from_form, from_yaml, leaf_fields, type_name
from app.ui import Input


class MessageForm:
    """Widgets for every leaf field of a message class, inside one folder.

    Numbers get number inputs, booleans checkboxes, text text inputs; lists
    and deeply nested parts are typed as YAML. ``message()`` builds the
    message or raises one ConversionError line.
    """

    MAX_FIELDS = 24

    def __init__(self, gui: viser.GuiApi, cls: type, title: str) -> None:
        self.cls = cls
        self._folder = gui.add_folder(title)
        self._widgets: dict[str, tuple[str, Input[object]]] = {}  # path -> (kind, widget)
        fields = leaf_fields(cls)
        with self._folder:
            if not fields:
                gui.add_markdown("_(no fields)_")
            self._yaml: viser.GuiTextHandle | None = None
            if len(fields) > self.MAX_FIELDS:
                self._yaml = gui.add_text("YAML", "{}", hint=f"fields of {type_name(cls)}")
                return
            for path, ros_type, kind in fields:
                label = f"{path} ({ros_type})"
                widget: Input[object]
                if kind == "bool":
                    widget = gui.add_checkbox(label, False)
                elif kind == "int":
                    widget = gui.add_number(label, 0, step=1)
                elif kind == "float":
                    widget = gui.add_number(label, 0.0, step=0.01)
                elif kind == "yaml":
                    widget = gui.add_text(label, "", hint="YAML, e.g. [1, 2, 3]")
                else:
                    widget = gui.add_text(label, "")
                self._widgets[path] = (kind, widget)

    def values(self) -> dict[str, object]:
        return {path: widget.value for path, (_kind, widget) in self._widgets.items()}

    def message(self) -> object:
        """A message of the form's class, or one ConversionError line."""
        if self._yaml is not None:
            return from_yaml(self.cls, self._yaml.value)
        values = self.values()
        for path, (kind, _w) in self._widgets.items():
            value = values[path]
            if kind == "int" and isinstance(value, float):
                if not value.is_integer():
                    raise ConversionError(f"field '{path}' needs a whole number")
                values[path] = int(value)
        return fill_from_form(self.cls, values)

    def remove(self) -> None:
        self._folder.remove()


class FormSlot:
    """A folder that holds the MessageForm of one message class at a time.

    Panels call ``show(key, build)`` whenever their selection may have
    changed; the form is rebuilt only when ``key`` differs from the one shown.
    """

    def __init__(self, gui: viser.GuiApi, title: str) -> None:
        self._gui = gui
        self._folder = gui.add_folder(title, expand_by_default=True)
        self._key: object = object()
        self.form: MessageForm | None = None

    def show(self, key: object, build: Callable[[], tuple[type, str]] | None) -> MessageForm | None:
        """The form for ``key``; ``build`` gives (message class, title), None for no form.

        A ConversionError from ``build`` propagates, leaving no form for ``key``.
        """
        if key == self._key:
            return self.form
        self._key = key
        if self.form is not None:
            self.form.remove()
            self.form = None
        if build is not None:
            cls, title = build()
            with self._folder:
                self.form = MessageForm(self._gui, cls, title)
        return self.form
