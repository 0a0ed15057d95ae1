"""JSON-shaped data, named once: what ``json.loads`` gives and ``json.dumps`` takes.

Data read from outside (a file, a token, a request) is best typed
``Mapping[str, object]`` and narrowed with ``isinstance`` where it is read;
``JSON`` is for what we build ourselves and hand to ``json.dumps`` or YAML.
"""

from __future__ import annotations

from typing import TypeAlias

JSON: TypeAlias = None | bool | int | float | str | list["JSON"] | dict[str, "JSON"]
JSONObject: TypeAlias = dict[str, JSON]
