"""Runs a process: its output prefixed ``[name-N]``, its start and end logged, its stop escalated.

As upstream: ``process started with pid [N]``, then each output line as
``[talker-1] line``, then ``process has finished cleanly [pid N]`` or
``process has died [pid N, exit code C, cmd '...'].``. On shutdown a process
gets SIGINT (unless the shutdown came from a Ctrl+C, which the terminal
already sent to the whole process group), then SIGTERM after
``sigterm_timeout`` seconds and SIGKILL ``sigkill_timeout`` seconds later
(5 and 5 by default, or the launch configurations of those names).
Children stay in the launcher's process group, so whoever signals that group
(a terminal's Ctrl+C, the classroom's supervisor) reaches every one of them.
"""

from __future__ import annotations

import asyncio
import ctypes
import os
import signal
import subprocess
from collections.abc import Callable, Iterable, Mapping
from typing import TYPE_CHECKING, Any

from ..action import Action
from ..event_handler import EventHandler
from ..events.process import (
    ProcessExited,
    ProcessStarted,
    ProcessStderr,
    ProcessStdout,
    ShutdownProcess,
    SignalProcess,
)
from ..events.shutdown import Shutdown
from ..logging import get_logger, get_output_logger, get_output_loggers
from ..substitutions.launch_configuration import LaunchConfiguration
from ..utilities import normalize_to_list_of_substitutions, perform_substitutions

if TYPE_CHECKING:
    from ..launch_context import LaunchContext
    from ..launch_description_entity import LaunchDescriptionEntity
    from ..substitution import Substitution

_PR_SET_PDEATHSIG = 1
_LINE_LIMIT = 1 << 20
_SIGTERM_TIMEOUT = LaunchConfiguration("sigterm_timeout", default=5)
_SIGKILL_TIMEOUT = LaunchConfiguration(
    "sigkill_timeout", default=5
)  # longest output line read at once


def _die_with_launcher() -> None:
    """In the child before exec: SIGTERM when the launcher dies, so no node is orphaned."""
    try:
        ctypes.CDLL(None).prctl(_PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
    except (OSError, AttributeError):
        pass


class ExecuteProcess(Action):
    def __init__(
        self,
        *,
        cmd: Iterable[Any],
        name: Any | None = None,
        cwd: Any | None = None,
        env: Mapping[Any, Any] | None = None,
        additional_env: Mapping[Any, Any] | None = None,
        shell: bool = False,
        sigterm_timeout: Any = _SIGTERM_TIMEOUT,
        sigkill_timeout: Any = _SIGKILL_TIMEOUT,
        emulate_tty: bool = False,
        output: Any = "log",
        output_format: str = "[{this.process_description.final_name}] {line}",
        cached_output: bool = False,
        log_cmd: bool = False,
        on_exit: Any | None = None,
        respawn: Any = False,
        respawn_delay: float | None = None,
        respawn_max_retries: int = -1,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.__cmd = [normalize_to_list_of_substitutions(part) for part in cmd]
        self.__name = None if name is None else normalize_to_list_of_substitutions(name)
        self.__cwd = None if cwd is None else normalize_to_list_of_substitutions(cwd)
        self.__env = (
            None
            if env is None
            else [
                (normalize_to_list_of_substitutions(k), normalize_to_list_of_substitutions(v))
                for k, v in env.items()
            ]
        )
        self.__additional_env = [
            (normalize_to_list_of_substitutions(k), normalize_to_list_of_substitutions(v))
            for k, v in (additional_env or {}).items()
        ]
        self.__shell = shell
        self.__sigterm_timeout = normalize_to_list_of_substitutions(sigterm_timeout)
        self.__sigkill_timeout = normalize_to_list_of_substitutions(sigkill_timeout)
        self.__emulate_tty = emulate_tty
        self.__output = normalize_to_list_of_substitutions(output)
        self.__output_format = output_format
        self.__log_cmd = log_cmd
        self.__on_exit = on_exit
        self.__respawn = normalize_to_list_of_substitutions(
            str(respawn) if isinstance(respawn, bool) else respawn
        )
        self.__respawn_delay = respawn_delay
        self.__respawn_max_retries = respawn_max_retries
        self.__respawn_retries = 0
        self.process_details: dict[str, Any] | None = None
        self.__process: asyncio.subprocess.Process | None = None
        self.__completed_future: asyncio.Future[None] | None = None
        self.__shutdown_started = False
        self.__escalation: asyncio.Task[None] | None = None
        self.__logger = get_logger()
        self.__label = ""

    # -- what the tutorials read -------------------------------------------

    @property
    def cmd(self) -> list[list[Substitution]]:
        return self.__cmd

    @property
    def name(self) -> list[Substitution] | None:
        return self.__name

    @property
    def output(self) -> list[Substitution]:
        return self.__output

    @property
    def shell(self) -> bool:
        return self.__shell

    @property
    def process_description(self) -> ExecuteProcess:
        return self  # upstream keeps these facts in an Executable; ``final_name`` is here

    @property
    def final_name(self) -> str:
        return self.__label

    def describe(self) -> str:
        return f"ExecuteProcess(cmd={[' + '.join(s.describe() for s in c) for c in self.__cmd]})"

    def get_asyncio_future(self) -> asyncio.Future[None] | None:
        return self.__completed_future

    # -- for subclasses (launch_ros.actions.Node) ---------------------------

    def _process_label_base(self, context: LaunchContext, cmd: list[str]) -> str:
        if self.__name is not None:
            return perform_substitutions(context, self.__name)
        return os.path.basename(cmd[0]) if cmd else "process"

    def _perform_cmd(self, context: LaunchContext) -> list[str]:
        return [perform_substitutions(context, part) for part in self.__cmd]

    # -- execution ---------------------------------------------------------

    def execute(self, context: LaunchContext) -> list[LaunchDescriptionEntity] | None:
        loop = context.asyncio_loop
        assert loop is not None, "ExecuteProcess needs a running launch service"
        cmd = self._perform_cmd(context)
        context.process_counter += 1
        self.__label = f"{self._process_label_base(context, cmd)}-{context.process_counter}"
        self.__logger = get_logger(self.__label)
        env = dict(context.environment)
        if self.__env is not None:
            env = {
                perform_substitutions(context, k): perform_substitutions(context, v)
                for k, v in self.__env
            }
        for k, v in self.__additional_env:
            env[perform_substitutions(context, k)] = perform_substitutions(context, v)
        if self.__emulate_tty:
            env.setdefault("PYTHONUNBUFFERED", "1")  # line by line, as on a terminal
        cwd = (
            None
            if self.__cwd is None
            else os.path.expanduser(perform_substitutions(context, self.__cwd))
        )
        output = perform_substitutions(context, self.__output)
        output = os.environ.get("OVERRIDE_LAUNCH_PROCESS_OUTPUT", output)
        stdout_to, stderr_to = get_output_loggers(self.__label, output)
        self.__stdout_logger = get_output_logger(self.__label, stdout_to)
        self.__stderr_logger = get_output_logger(self.__label, stderr_to)
        respawn = perform_substitutions(context, self.__respawn).strip().lower() in ("true", "1")
        self.__sigterm_sec = perform_substitutions(context, self.__sigterm_timeout)
        self.__sigkill_sec = perform_substitutions(context, self.__sigkill_timeout)
        float(self.__sigterm_sec), float(self.__sigkill_sec)  # a bad timeout fails here
        self.process_details = {
            "name": self.__label,
            "cmd": cmd,
            "cwd": cwd,
            "env": env,
            "pid": None,
        }
        self.__completed_future = loop.create_future()
        matches_me: Callable[[Any], bool] = lambda item: item is self  # noqa: E731
        context.register_event_handler(
            EventHandler(
                matcher=lambda e: isinstance(e, ShutdownProcess) and e.process_matcher(self),
                entities=[_Call(lambda c: self._shutdown_process(c, send_sigint=True))],
            )
        )
        context.register_event_handler(
            EventHandler(
                matcher=lambda e: isinstance(e, SignalProcess) and e.process_matcher(self),
                entities=[_Call(self._on_signal_process)],
            )
        )
        context.register_event_handler(
            EventHandler(
                matcher=lambda e: isinstance(e, Shutdown),
                entities=[_Call(self._on_shutdown)],
            )
        )
        if self.__on_exit is not None:
            from ..event_handlers import OnProcessExit

            context.register_event_handler(
                OnProcessExit(target_action=matches_me, on_exit=self.__on_exit)
            )
        if context.is_shutdown:
            self.__completed_future.set_result(None)
            return None
        loop.create_task(self.__run(context, cmd, env, cwd, respawn))
        return None

    async def __run(
        self,
        context: LaunchContext,
        cmd: list[str],
        env: dict[str, str],
        cwd: str | None,
        respawn: bool,
    ) -> None:
        argv = ["/bin/sh", "-c", " ".join(cmd)] if self.__shell else cmd
        if self.__log_cmd:
            self.__logger.info(
                f"process details: cmd='{' '.join(cmd)}', cwd='{cwd}', "
                f"custom_env?={self.__env is not None}"
            )
        try:
            process = await asyncio.create_subprocess_exec(
                *argv,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                cwd=cwd,
                env=env,
                limit=_LINE_LIMIT,
                preexec_fn=_die_with_launcher,
            )
        except Exception as exc:
            self.__logger.error(f"exception occurred while executing process:\n{exc}")
            self.__finish(context)
            return
        self.__process = process
        pid = process.pid
        assert self.process_details is not None
        self.process_details["pid"] = pid
        details: dict[str, Any] = {
            "action": self,
            "name": self.__label,
            "cmd": cmd,
            "cwd": cwd,
            "env": env,
            "pid": pid,
        }
        self.__logger.info(f"process started with pid [{pid}]")
        context.emit_event_sync(ProcessStarted(**details))
        assert process.stdout is not None and process.stderr is not None
        readers = [
            asyncio.ensure_future(
                self.__pump(context, process.stdout, ProcessStdout, details, self.__stdout_logger)
            ),
            asyncio.ensure_future(
                self.__pump(context, process.stderr, ProcessStderr, details, self.__stderr_logger)
            ),
        ]
        returncode = await process.wait()
        # A grandchild may hold the pipes open: read what is there, then stop reading.
        _done, pending = await asyncio.wait(readers, timeout=1.0)
        for reader in pending:
            reader.cancel()
        if returncode == 0:
            self.__logger.info(f"process has finished cleanly [pid {pid}]")
        else:
            shown = " ".join(part for part in cmd if part.strip())
            self.__logger.error(
                f"process has died [pid {pid}, exit code {returncode}, cmd '{shown}']."
            )
        context.emit_event_sync(ProcessExited(returncode=returncode, **details))
        if (
            respawn
            and not context.is_shutdown
            and not self.__shutdown_started
            and (
                self.__respawn_max_retries < 0
                or self.__respawn_retries < self.__respawn_max_retries
            )
        ):
            self.__respawn_retries += 1
            if self.__respawn_delay:
                await asyncio.sleep(self.__respawn_delay)
            if not context.is_shutdown and not self.__shutdown_started:
                await self.__run(context, cmd, env, cwd, respawn)
                return
        self.__finish(context)

    def __finish(self, context: LaunchContext) -> None:
        if self.__escalation is not None:
            self.__escalation.cancel()
        if self.__completed_future is not None and not self.__completed_future.done():
            self.__completed_future.set_result(None)

    async def __pump(
        self,
        context: LaunchContext,
        stream: asyncio.StreamReader,
        event_type: type,
        details: dict[str, Any],
        logger: Any,
    ) -> None:
        while True:
            try:
                raw = await stream.readline()
            except ValueError:  # a line longer than the limit: take what there is
                raw = await stream.read(_LINE_LIMIT)
            if not raw:
                return
            context.emit_event_sync(event_type(text=raw, **details))
            line = raw.decode("utf-8", errors="replace").rstrip("\r\n")
            logger.info(self.__output_format.format(line=line, this=self))

    # -- stopping ----------------------------------------------------------

    def _on_shutdown(self, context: LaunchContext) -> None:
        event = context.locals.event
        due_to_sigint = bool(getattr(event, "due_to_sigint", False))
        self._shutdown_process(context, send_sigint=not due_to_sigint or context.noninteractive)

    def _shutdown_process(self, context: LaunchContext, *, send_sigint: bool) -> None:
        if self.__shutdown_started:
            return
        self.__shutdown_started = True
        process = self.__process
        if process is None or process.returncode is not None:
            return  # not started (it will not be now) or already ended
        if send_sigint:
            self._send(signal.SIGINT)
        loop = context.asyncio_loop
        assert loop is not None
        self.__escalation = loop.create_task(self.__escalate())

    async def __escalate(self) -> None:
        term = float(self.__sigterm_sec)
        kill = float(self.__sigkill_sec)
        base = (
            "process[{}] failed to terminate '{}' seconds after receiving '{}', escalating to '{}'"
        )
        await asyncio.sleep(term)
        if self.__process is None or self.__process.returncode is not None:
            return
        self.__logger.error(base.format(self.__label, self.__sigterm_sec, "SIGINT", "SIGTERM"))
        self._send(signal.SIGTERM)
        await asyncio.sleep(kill)
        if self.__process is None or self.__process.returncode is not None:
            return
        self.__logger.error(base.format(self.__label, term + kill, "SIGTERM", "SIGKILL"))
        self._send("SIGKILL")

    def _on_signal_process(self, context: LaunchContext) -> None:
        event = context.locals.event
        self._send(event.signal)

    def _send(self, sig: Any) -> None:
        process = self.__process
        if process is None or process.returncode is not None:
            return
        name = sig if isinstance(sig, str) else signal.Signals(sig).name
        self.__logger.info(f"sending signal '{name}' to process[{self.__label}]")
        try:
            if name == "SIGKILL":
                process.kill()
            else:
                process.send_signal(sig)
        except ProcessLookupError:
            pass


class _Call(Action):
    """An internal action that calls ``function(context)``."""

    def __init__(self, function: Callable[[LaunchContext], None]) -> None:
        super().__init__()
        self.__function = function

    def execute(self, context: LaunchContext) -> None:
        self.__function(context)
