"""The base of everything a launch description holds (actions, descriptions)."""

from __future__ import annotations

import asyncio
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .launch_context import LaunchContext


class LaunchDescriptionEntity:
    """Something the launch service visits; visiting may yield more entities."""

    def describe(self) -> str:
        return f"{type(self).__name__}()"

    def visit(self, context: LaunchContext) -> list[LaunchDescriptionEntity] | None:
        return None

    def get_asyncio_future(self) -> asyncio.Future | None:
        """A future that is pending while this entity still has work under way."""
        return None
