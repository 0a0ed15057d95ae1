"""The launch service: visits launch descriptions, dispatches events, shuts down cleanly.

One asyncio loop on the calling thread. Ctrl+C (SIGINT) logs upstream's
``user interrupted with ctrl-c (SIGINT)`` and shuts down; each process then
ends on its own SIGINT or is escalated (see ExecuteProcess). SIGTERM shuts
down the same way (upstream only logs and cancels, which can orphan
processes). Every shutdown is bounded: ``SHUTDOWN_BOUND_SEC`` after it began
the service returns whatever is left, and the processes' parent-death signal
ends them.
"""

from __future__ import annotations

import asyncio
import os
import signal
import sys
import threading
import traceback
from collections.abc import Iterable
from typing import Any

from .action import Action
from .event import Event
from .event_handler import BaseEventHandler
from .events.execution_complete import ExecutionComplete
from .events.include_launch_description import IncludeLaunchDescription
from .events.shutdown import Shutdown
from .invalid_launch_file_error import InvalidLaunchFileError
from .launch_context import LaunchContext
from .launch_description import LaunchDescription
from .launch_description_entity import LaunchDescriptionEntity
from .logging import get_logger, launch_config
from .utilities import normalize_to_list_of_entities

SHUTDOWN_BOUND_SEC = 15.0  # past the default SIGINT -> SIGTERM -> SIGKILL escalation (10 s)


class LaunchService:
    def __init__(
        self,
        *,
        argv: Iterable[str] | None = None,
        noninteractive: bool = False,
        debug: bool = False,
    ) -> None:
        self.__context = LaunchContext(argv=argv, noninteractive=noninteractive)
        self.__debug = debug
        self.__logger = get_logger("launch")
        self.__shutting_down = False
        self.__shutdown_began: float | None = None
        self.__return_code = 0
        self.__futures: list[tuple[LaunchDescriptionEntity, asyncio.Future[Any]]] = []
        self.__loop: asyncio.AbstractEventLoop | None = None
        self.__wakeup: asyncio.Event | None = None
        self.__running = threading.Event()
        self.__context.register_event_handler(_Builtin(self))

    @property
    def context(self) -> LaunchContext:
        return self.__context

    @property
    def event_loop(self) -> asyncio.AbstractEventLoop | None:
        return self.__loop

    def include_launch_description(self, launch_description: Any) -> None:
        """Queue a launch description (or a source of one) to be visited."""
        if isinstance(launch_description, LaunchDescriptionEntity) and not isinstance(
            launch_description, LaunchDescription
        ):
            launch_description = LaunchDescription([launch_description])
        elif not isinstance(launch_description, LaunchDescription):
            from .actions.include_launch_description import (
                IncludeLaunchDescription as IncludeAction,
            )

            launch_description = LaunchDescription([IncludeAction(launch_description)])
        self.__emit_threadsafe(IncludeLaunchDescription(launch_description))

    def emit_event(self, event: Event) -> None:
        self.__emit_threadsafe(event)

    def shutdown(self, force_sync: bool = False) -> None:
        """Ask the running service to shut down (safe from any thread)."""
        self.__emit_threadsafe(Shutdown(reason="LaunchService.shutdown() called"))

    def __emit_threadsafe(self, event: Event) -> None:
        loop = self.__loop
        if loop is not None and self.__running.is_set():
            loop.call_soon_threadsafe(self.__context.emit_event_sync, event)
        else:
            self.__context.emit_event_sync(event)

    def run(self, *, shutdown_when_idle: bool = True) -> int:
        loop = asyncio.new_event_loop()
        try:
            return loop.run_until_complete(self.run_async(shutdown_when_idle=shutdown_when_idle))
        finally:
            pending = [t for t in asyncio.all_tasks(loop) if not t.done()]
            for task in pending:
                task.cancel()
            if pending:
                loop.run_until_complete(asyncio.gather(*pending, return_exceptions=True))
            loop.close()

    async def run_async(self, *, shutdown_when_idle: bool = True) -> int:
        loop = asyncio.get_running_loop()
        self.__loop = loop
        self.__context._set_asyncio_loop(loop)
        loop.set_exception_handler(self.__on_loop_exception)
        self.__logger.info(f"All log files can be found below {launch_config.log_dir}")
        self.__logger.info("Default logging verbosity is set to INFO")
        handled: list[int] = []
        if threading.current_thread() is threading.main_thread():
            sigint_seen = False

            def on_sigint() -> None:
                nonlocal sigint_seen
                message = "user interrupted with ctrl-c (SIGINT)"
                if sigint_seen:
                    self.__logger.warning(f"{message} again, ignoring...")
                    return
                sigint_seen = True
                self.__logger.warning(message)
                self.__context.emit_event_sync(
                    Shutdown(reason="ctrl-c (SIGINT)", due_to_sigint=True)
                )

            def on_sigterm(signum: int) -> None:
                name = signal.Signals(signum).name
                self.__logger.error(f"user interrupted with ctrl-\\ ({name}), terminating...")
                self.__context.emit_event_sync(Shutdown(reason=name))

            loop.add_signal_handler(signal.SIGINT, on_sigint)
            loop.add_signal_handler(signal.SIGTERM, on_sigterm, signal.SIGTERM)
            loop.add_signal_handler(signal.SIGQUIT, on_sigterm, signal.SIGQUIT)
            handled = [signal.SIGINT, signal.SIGTERM, signal.SIGQUIT]
        self.__running.set()
        try:
            await self.__main_loop(shutdown_when_idle)
        finally:
            self.__running.clear()
            for sig in handled:
                loop.remove_signal_handler(sig)
        return self.__return_code

    async def __main_loop(self, shutdown_when_idle: bool) -> None:
        queue = self.__context._event_queue
        assert queue is not None
        loop = asyncio.get_running_loop()
        while True:
            while not queue.empty():
                await self.__process_event(queue.get_nowait())
            self.__reap_futures()
            if not queue.empty():
                continue
            pending = [f for _e, f in self.__futures if not f.done()]
            if not pending:
                if self.__shutting_down:
                    return
                if shutdown_when_idle:
                    self.__context.emit_event_sync(Shutdown(reason="idle"))
                    continue
            if self.__shutting_down and self.__shutdown_began is not None:
                if loop.time() - self.__shutdown_began > SHUTDOWN_BOUND_SEC:
                    self.__logger.error(
                        f"shutdown took longer than {SHUTDOWN_BOUND_SEC:g} s, giving up waiting"
                    )
                    return
            getter = asyncio.ensure_future(queue.get())
            done, _ = await asyncio.wait(
                [getter, *pending], timeout=0.5, return_when=asyncio.FIRST_COMPLETED
            )
            if getter in done:
                await self.__process_event(getter.result())
            else:
                getter.cancel()
                try:
                    await getter
                except asyncio.CancelledError:
                    pass

    def __reap_futures(self) -> None:
        still = []
        for entity, future in self.__futures:
            if future.done():
                if isinstance(entity, Action):
                    self.__context.emit_event_sync(ExecutionComplete(action=entity))
            else:
                still.append((entity, future))
        self.__futures = still

    async def __process_event(self, event: Event) -> None:
        context = self.__context
        for handler in list(context._event_handlers):
            if handler not in context._event_handlers or not handler.matches(event):
                continue
            context._push_locals()
            try:
                entities = handler.handle(event, context)
                for entity in normalize_to_list_of_entities(entities):
                    self.__visit(entity)
            except Exception as exc:
                self.__fail(exc)
            finally:
                context._pop_locals()

    def __visit(self, entity: LaunchDescriptionEntity) -> None:
        if not isinstance(entity, LaunchDescriptionEntity):
            raise TypeError(
                f"expected a launch description entity (an action), got "
                f"'{type(entity).__name__}': {entity!r}"
            )
        sub_entities = entity.visit(self.__context)
        future = entity.get_asyncio_future()
        if future is not None:
            self.__futures.append((entity, future))
        elif isinstance(entity, Action):
            self.__context.emit_event_sync(ExecutionComplete(action=entity))
        for sub in sub_entities or []:
            self.__visit(sub)

    def __fail(self, exc: BaseException) -> None:
        self.__logger.error(f"Caught exception in launch (see debug for traceback): {exc}")
        if self.__debug:
            self.__logger.error("".join(traceback.format_exception(exc)))
        elif isinstance(exc, InvalidLaunchFileError):
            _print_launch_file_traceback(exc)
        self.__return_code = 1
        if not self.__shutting_down:
            self.__context.emit_event_sync(Shutdown(reason="exception in launch"))

    def __on_loop_exception(self, loop: asyncio.AbstractEventLoop, info: dict[str, Any]) -> None:
        exc = info.get("exception")
        self.__fail(exc if exc is not None else RuntimeError(info.get("message", "?")))

    def _on_shutdown(self, event: Shutdown) -> None:
        if not self.__shutting_down:
            self.__shutting_down = True
            assert self.__loop is not None
            self.__shutdown_began = self.__loop.time()
            self.__context._set_is_shutdown(True)


def _print_launch_file_traceback(exc: InvalidLaunchFileError) -> None:
    """The frames of the launch file itself, so an error points at its line.

    (Upstream shows tracebacks only with ``--debug``; a learner needs the line.)
    """
    for error in exc.likely_errors:
        if isinstance(error, SyntaxError):
            continue  # its message already names the file and line
        tb = error.__traceback__
        while tb is not None and not tb.tb_frame.f_code.co_filename.endswith(".py"):
            tb = tb.tb_next
        frames = []
        while tb is not None:
            if "launch" in os.path.basename(tb.tb_frame.f_code.co_filename) or (
                tb.tb_frame.f_code.co_name == "generate_launch_description"
            ):
                frames.append(tb)
            tb = tb.tb_next
        if frames:
            print(
                "".join(traceback.format_exception(type(error), error, frames[0])),
                end="",
                file=sys.stderr,
                flush=True,
            )


class _Builtin(BaseEventHandler):
    """The service's own handling of IncludeLaunchDescription and Shutdown events."""

    def __init__(self, service: LaunchService) -> None:
        super().__init__(matcher=lambda e: isinstance(e, (IncludeLaunchDescription, Shutdown)))
        self.__service = service

    def handle(self, event: Event, context: LaunchContext) -> Any:
        super().handle(event, context)
        if isinstance(event, IncludeLaunchDescription):
            return [event.launch_description]
        assert isinstance(event, Shutdown)
        self.__service._on_shutdown(event)
        return None
