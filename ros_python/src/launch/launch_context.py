"""The state a launch run shares: launch configurations, environment, locals, events."""

from __future__ import annotations

import asyncio
import collections
import os
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .event import Event
    from .event_handler import BaseEventHandler
    from .substitution import Substitution


class _Locals:
    """Attribute access to the merged stack of locals (``context.locals.event``)."""

    def __init__(self, context: LaunchContext) -> None:
        self.__dict__["_context"] = context

    def __getattr__(self, key: str) -> Any:
        for frame in reversed(self._context._locals_stack):
            if key in frame:
                return frame[key]
        raise AttributeError(
            f"context.locals does not contain attribute '{key}', it contains: "
            f"[{', '.join(self._context.get_locals_as_dict())}]"
        )


class LaunchContext:
    """Passed to every visit, substitution and event handler of one launch."""

    def __init__(self, *, argv: Iterable[str] | None = None, noninteractive: bool = False):
        self.__argv = list(argv) if argv is not None else []
        self.__noninteractive = noninteractive
        self._locals_stack: list[dict[str, Any]] = [{}]
        self.__locals = _Locals(self)
        self.launch_configurations: dict[str, Any] = {}
        self.__launch_configurations_stack: list[dict[str, Any]] = []
        self.environment: dict[str, str] = dict(os.environ)
        self.__environment_stack: list[dict[str, str]] = []
        self._event_queue: asyncio.Queue[Event] | None = None
        self._event_handlers: collections.deque[BaseEventHandler] = collections.deque()
        self.__asyncio_loop: asyncio.AbstractEventLoop | None = None
        self.__is_shutdown = False
        self._pending_events: list[Event] = []  # emitted before the loop exists
        self._completion_futures: list[asyncio.Future[Any]] = []
        self.process_counter = 0  # labels processes name-1, name-2, ... in start order

    # -- read-only facts ---------------------------------------------------

    @property
    def argv(self) -> list[str]:
        return self.__argv

    @property
    def noninteractive(self) -> bool:
        return self.__noninteractive

    @property
    def is_shutdown(self) -> bool:
        return self.__is_shutdown

    def _set_is_shutdown(self, value: bool) -> None:
        self.__is_shutdown = value

    @property
    def asyncio_loop(self) -> asyncio.AbstractEventLoop | None:
        return self.__asyncio_loop

    def _set_asyncio_loop(self, loop: asyncio.AbstractEventLoop) -> None:
        self.__asyncio_loop = loop
        self._event_queue = asyncio.Queue()
        for event in self._pending_events:
            self._event_queue.put_nowait(event)
        self._pending_events.clear()

    # -- locals ------------------------------------------------------------

    @property
    def locals(self) -> Any:
        return self.__locals

    def extend_locals(self, new_locals: Mapping[str, Any]) -> None:
        self._locals_stack[-1].update(new_locals)

    def _push_locals(self) -> None:
        self._locals_stack.append({})

    def _pop_locals(self) -> None:
        if len(self._locals_stack) > 1:
            self._locals_stack.pop()

    def get_locals_as_dict(self) -> dict[str, Any]:
        merged: dict[str, Any] = {}
        for frame in self._locals_stack:
            merged.update(frame)
        return merged

    # -- scopes (GroupAction) ----------------------------------------------

    def _push_launch_configurations(self) -> None:
        self.__launch_configurations_stack.append(dict(self.launch_configurations))

    def _pop_launch_configurations(self) -> None:
        if not self.__launch_configurations_stack:
            raise RuntimeError("launch_configurations stack unexpectedly empty")
        self.launch_configurations = self.__launch_configurations_stack.pop()

    def _push_environment(self) -> None:
        self.__environment_stack.append(dict(self.environment))

    def _pop_environment(self) -> None:
        if not self.__environment_stack:
            raise RuntimeError("environment stack unexpectedly empty")
        self.environment = self.__environment_stack.pop()

    # -- events ------------------------------------------------------------

    def register_event_handler(self, event_handler: BaseEventHandler, append: bool = False) -> None:
        if append:
            self._event_handlers.append(event_handler)
        else:
            self._event_handlers.appendleft(event_handler)

    def unregister_event_handler(self, event_handler: BaseEventHandler) -> None:
        try:
            self._event_handlers.remove(event_handler)
        except ValueError:
            raise RuntimeError(f"Event handler not found: {event_handler}") from None

    def emit_event_sync(self, event: Event) -> None:
        if self._event_queue is None:
            self._pending_events.append(event)
        else:
            self._event_queue.put_nowait(event)

    async def emit_event(self, event: Event) -> None:
        self.emit_event_sync(event)

    def add_completion_future(self, future: asyncio.Future[Any]) -> None:
        self._completion_futures.append(future)

    # -- substitutions -----------------------------------------------------

    def perform_substitution(self, substitution: Substitution) -> str:
        return substitution.perform(self)
