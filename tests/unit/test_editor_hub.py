"""The code editor's server over a real websocket: workspace files in tabs, lint as the
learner types, completion from Jedi, ruff's format, confinement (no browser, no ROS graph)."""

from __future__ import annotations

import asyncio
import concurrent.futures
import json
import os
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from websockets.asyncio.client import connect
from websockets.asyncio.server import serve

from app.exercises import code_assist
from app.exercises.editor_server import SOCKET_PATH, EditorHub
from app.learner_ws import folder, overlay
from app.learner_ws.folder import LearnerWorkspace

NODE = (
    "import rclpy\n\n\ndef main():\n    rclpy.init()\n    node = rclpy.create_node('n')\n"
    "    node.destroy_node()\n"
)


@pytest.fixture
def ws(tmp_path) -> Iterator[LearnerWorkspace]:
    workspace = LearnerWorkspace(tmp_path / "ros2_ws")
    folder.configure(workspace)
    pkg = workspace.src / "my_package" / "my_package"
    pkg.mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "my_node.py").write_text(NODE)
    (pkg / "helper.py").write_text(
        "def shout(text: str, times: int = 2) -> str:\n    return text\n"
    )
    (workspace.src / "my_package" / "package.xml").write_text("<package/>\n")
    (tmp_path / "secret.txt").write_text("not yours\n")
    yield workspace
    folder.configure(None)


class Editor:
    """One editor's socket: send a message, wait for the answer of a type."""

    def __init__(self, socket: Any) -> None:
        self.socket = socket
        self.seen: list[dict[str, Any]] = []

    async def send(self, **message: Any) -> None:
        await self.socket.send(json.dumps(message))

    async def expect(self, kind: str, timeout: float = 30.0, **fields: Any) -> dict[str, Any]:
        deadline = time.monotonic() + timeout
        for message in self.seen:
            if message["type"] == kind and all(message.get(k) == v for k, v in fields.items()):
                self.seen.remove(message)
                return message
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                raise AssertionError(f"no {kind} {fields} within {timeout} s; saw {self.seen}")
            message = json.loads(await asyncio.wait_for(self.socket.recv(), left))
            if message["type"] == kind and all(message.get(k) == v for k, v in fields.items()):
                return message
            self.seen.append(message)


def run_with_editor(
    hub: EditorHub, test: Any, slug: str = "heartbeat_logger", *, first_load: bool = True
) -> None:
    """``test(editor, url)`` with an editor connected; by default after its first load."""

    async def main() -> None:
        async def refuse(connection: Any) -> None:
            raise AssertionError("only the editor's socket is used here")

        async with serve(hub.wrap_handler(refuse), "127.0.0.1", 0) as server:
            port = server.sockets[0].getsockname()[1]
            url = f"ws://127.0.0.1:{port}{SOCKET_PATH}?slug={slug}"
            async with connect(url) as socket:
                editor = Editor(socket)
                if first_load:
                    await editor.expect("load", file=None)  # the exercise's code, as before
                await test(editor, url)

    # Its own thread: the session's Playwright (browser tests) keeps an asyncio loop
    # running on the main thread, where asyncio.run would refuse to start.
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        pool.submit(asyncio.run, main()).result()


@pytest.fixture
def hub(tmp_path) -> Iterator[EditorHub]:
    saved: dict[str, str] = {}
    hub = EditorHub()
    hub.attach(lambda slug: saved.get(slug, "print('starter')\n"), saved.__setitem__,
               scratch=tmp_path)  # fmt: skip
    hub.saved = saved  # type: ignore[attr-defined]
    yield hub
    hub.close()


def test_two_workspace_files_open_save_atomically_and_lint_on_every_save(hub, ws, tmp_path):
    node = ws.src / "my_package" / "my_package" / "my_node.py"

    async def test(editor: Editor, url: str) -> None:
        await editor.send(type="tree", folder="")
        tree = await editor.expect("tree", folder="")
        assert [e["path"] for e in tree["entries"]] == ["src"]
        await editor.send(type="tree", folder="src/my_package/my_package")
        listed = await editor.expect("tree", folder="src/my_package/my_package")
        assert [e["path"].rsplit("/", 1)[1] for e in listed["entries"]] == [
            "__init__.py", "helper.py", "my_node.py"
        ]  # fmt: skip
        for name in ("my_node.py", "helper.py"):
            await editor.send(type="open", file=f"~/ros2_ws/src/my_package/my_package/{name}")
        first = await editor.expect("load", file="src/my_package/my_package/my_node.py")
        await editor.expect("load", file="src/my_package/my_package/helper.py")
        assert first["code"] == NODE
        assert (await editor.expect("problems", file=first["file"]))["items"] == []
        # An undefined name: a mark comes back with the save, no Run needed.
        code = NODE + "    print(undefined_thing)\n"
        await editor.send(type="save", file=first["file"], code=code, rev=1)
        assert (await editor.expect("saved", file=first["file"]))["rev"] == 1
        marks = await editor.expect("problems", file=first["file"])
        assert marks["items"] == [
            {"row": 7, "column": 10, "text": "undefined name 'undefined_thing'", "type": "warning"}
        ]
        assert node.read_text() == code
        assert oct(node.stat().st_mode & 0o777) == oct(0o644)  # mode kept, not mkstemp's 0600
        assert not [p for p in node.parent.iterdir() if p.name.startswith(".")]  # no temp left
        # The exercise's own file is still saved through the exercise workspace.
        await editor.expect("problems", file="")  # the exercise's marks when it loaded
        await editor.send(type="save", code="x = (\n", rev=2)
        await editor.expect("saved", file="", rev=2)
        fatal = await editor.expect("problems", file="")
        assert fatal["items"][0]["type"] == "error"
        assert hub.saved["heartbeat_logger"] == "x = (\n"

    run_with_editor(hub, test)


def test_paths_outside_the_workspace_and_non_text_files_are_refused(hub, ws, tmp_path):
    (ws.root / "blob.bin").write_bytes(b"\x00\x01\x02")
    (ws.root / "escape").symlink_to(tmp_path)

    async def test(editor: Editor, url: str) -> None:
        for bad in ("../secret.txt", str(tmp_path / "secret.txt"), "escape/secret.txt"):
            await editor.send(type="open", file=bad)
            error = await editor.expect("error", file=bad)
            assert "outside your workspace" in error["text"]
            await editor.send(type="save", file=bad, code="pwned\n", rev=1)
            assert "outside your workspace" in (await editor.expect("error", file=bad))["text"]
        await editor.send(type="open", file="blob.bin")
        assert "not a text file" in (await editor.expect("error", file="blob.bin"))["text"]
        await editor.send(type="tree", folder="../")
        assert "outside your workspace" in (await editor.expect("tree", folder="../"))["note"]

    run_with_editor(hub, test)
    assert (tmp_path / "secret.txt").read_text() == "not yours\n"


def test_a_change_on_disk_reaches_the_open_tab_and_a_deleted_file_closes_it(hub, ws):
    helper = ws.src / "my_package" / "my_package" / "helper.py"

    async def test(editor: Editor, url: str) -> None:
        await editor.send(type="open", file="src/my_package/my_package/helper.py")
        await editor.expect("load", file="src/my_package/my_package/helper.py")
        await asyncio.sleep(0.05)
        helper.write_text("def shout():\n    return 'changed by the Console'\n")
        changed = await editor.expect("load", file="src/my_package/my_package/helper.py")
        assert "changed by the Console" in changed["code"]
        assert changed["note"] == "changed on disk: reloaded"
        helper.unlink()
        closed = await editor.expect("closed", file="src/my_package/my_package/helper.py")
        assert "deleted or renamed" in closed["note"]

    run_with_editor(hub, test)


def test_format_returns_ruffs_text_or_the_syntax_error(hub, ws):
    async def test(editor: Editor, url: str) -> None:
        await editor.send(type="format", file="src/x.py", code="x = [1,2,\n  3]\n", rev=4)
        done = await editor.expect("formatted", file="src/x.py")
        assert done == {
            "type": "formatted",
            "file": "src/x.py",
            "rev": 4,
            "code": "x = [1, 2, 3]\n",
        }
        await editor.send(type="format", file="src/x.py", code="def f(:\n", rev=5)
        failed = await editor.expect("formatted", file="src/x.py", rev=5)
        assert failed["error"].startswith("cannot format: line 1: ")

    run_with_editor(hub, test)


def test_completion_signatures_and_docs_for_rclpy_and_the_learners_own_modules(hub, ws, tmp_path):
    """Jedi in its own process: rclpy, a message type, the package's module, and an
    interface package of a sourced install space (its Python folder on Jedi's path)."""
    site = tmp_path / "ros2_ws" / "install" / "my_interfaces" / "lib" / "python3.11"
    msg = site / "site-packages" / "my_interfaces" / "msg"
    msg.mkdir(parents=True)
    (msg.parent / "__init__.py").write_text("")
    (msg / "__init__.py").write_text("from my_interfaces.msg._num import Num  # noqa: F401\n")
    (msg / "_num.py").write_text("class Num:\n    def __init__(self, num: int = 0):\n"
                                 "        self.num = num\n")  # fmt: skip
    index = ws.root / "install" / "my_interfaces" / overlay.INDEX / "my_interfaces"
    index.parent.mkdir(parents=True)
    index.write_text("")
    code = NODE + "    node.create_pub"
    row, column = code.count("\n"), len(code.rsplit("\n", 1)[1])
    where = {"file": "src/my_package/my_package/my_node.py", "row": row, "column": column}

    async def ask(editor: Editor, kind: str, ident: int, **fields: Any) -> dict[str, Any]:
        await editor.send(type=kind, id=ident, **fields)
        return await editor.expect(kind, timeout=60, id=ident)

    async def test(editor: Editor, url: str) -> None:
        assert (await editor.expect("assist"))["completion"] is True
        done = await ask(editor, "complete", 1, code=code, **where)
        assert [i["name"] for i in done["items"]] == ["create_publisher"], done
        doc = await ask(editor, "doc", 2, code=code, name="create_publisher", **where)
        assert doc["items"]["signatures"][0].startswith(
            "create_publisher(msg_type, topic: str, qos_profile:"
        )
        call = code + "lisher(String, "
        sig = await ask(editor, "signatures", 3, code=call, **{**where, "column": column + 15})
        assert sig["items"][0]["index"] == 1 and sig["items"][0]["params"][1] == "topic: str"
        own = "from my_package.helper import shout\nshout("
        mine = await ask(editor, "signatures", 4, code=own, row=1, column=6, file=where["file"])
        assert mine["items"][0]["label"] == "shout(text: str, times: int=2) -> str"
        message = "from std_msgs.msg import String\nm = String()\nm.da"
        field = await ask(editor, "complete", 5, code=message, row=2, column=4, file="x.py")
        assert [i["name"] for i in field["items"]] == ["data"]
        # Not sourced yet: the learner's interface package is unknown; sourced, it is known.
        theirs = "from my_interfaces.msg import Num\nNum().nu"
        before = await ask(editor, "complete", 6, code=theirs, row=1, column=8, file="x.py")
        assert before["items"] == []
        overlay.source(ws.root / "install")
        try:
            after = await ask(editor, "complete", 7, code=theirs, row=1, column=8, file="x.py")
        finally:
            overlay.forget()
        assert [i["name"] for i in after["items"]] == ["num"]

    run_with_editor(hub, test)


def test_the_worker_starts_again_after_it_died(ws):
    pause = 0.5
    process = code_assist.AssistProcess(lambda: code_assist.worker_argv(None, None), None, pause)
    try:
        request = {"op": "complete", "code": "import o", "path": "/tmp/x.py", "line": 1,
                   "column": 8, "sys_path": []}  # fmt: skip
        assert {"name": "os", "type": "module", "module": "os"} in process.request(request).result(
            60
        )["items"]
        pid = process._proc.pid  # type: ignore[union-attr]
        os.kill(pid, 9)
        time.sleep(pause)
        again = process.request(request).result(60)
        assert {"name": "os", "type": "module", "module": "os"} in again["items"]
        assert process._proc.pid != pid  # type: ignore[union-attr]
    finally:
        process.close()


def test_served_dashboards_run_the_worker_contained_or_not_at_all(tmp_path):
    from app.containment.policy import RunPolicy

    policy = RunPolicy(allowed=False, contained=True, hidden=(tmp_path / "others",))
    argv = code_assist.worker_argv(policy, tmp_path)
    assert argv[1].endswith("contain.py") and "--no-ros" in argv
    assert argv[-1] == str(code_assist.WORKER)
    assert code_assist.worker_argv(RunPolicy(), None)[1:] == [str(code_assist.WORKER)]


def test_the_page_files_are_the_editors_and_aces(tmp_path):
    from app.exercises.editor_server import ACE_DIR, PREFIX, _file_for

    assert _file_for(PREFIX + "ace/ext-language_tools.js") == ACE_DIR / "ext-language_tools.js"
    assert _file_for(PREFIX + "assist_worker.py") is None
    assert Path(code_assist.WORKER).is_file()


def test_an_editor_that_connects_before_the_panel_is_built_loses_no_save(tmp_path):
    # The web server serves while the dashboard still builds its panels: an editor
    # reloaded then used to get "" as its code and an acknowledged save that went
    # nowhere (a SIGKILL right after lost the learner's code).
    saved: dict[str, str] = {}
    hub = EditorHub()

    async def attach_later() -> None:
        await asyncio.sleep(0.5)
        hub.attach(lambda slug: saved.get(slug, "print('starter')\n"), saved.__setitem__,
                   scratch=tmp_path)  # fmt: skip

    async def test(editor: Editor, url: str) -> None:
        attaching = asyncio.create_task(attach_later())
        await editor.send(type="save", code="print('mine')\n", rev=1)
        loaded = await editor.expect("load", file=None)
        assert loaded["code"] == "print('starter')\n"  # the exercise's, not ""
        await editor.expect("saved", rev=1)
        assert saved == {"heartbeat_logger": "print('mine')\n"}
        await attaching

    try:
        run_with_editor(hub, test, first_load=False)
    finally:
        hub.close()


def test_close_ends_the_hubs_tasks_while_the_servers_loop_still_runs(hub, ws, caplog):
    """Shutdown: the file watcher an editor started ends before viser's loop stops; left
    pending, the dropped loop logged "Task was destroyed but it is pending!" as an ERROR
    (rehearsal ci78: 12 dashboards' logs ended so)."""
    import gc
    import threading

    loop = asyncio.new_event_loop()
    thread = threading.Thread(target=loop.run_forever, daemon=True)
    thread.start()
    connected = threading.Event()

    async def serve_one_editor() -> Any:
        async def refuse(connection: Any) -> None:
            raise AssertionError("only the editor's socket is used here")

        server = await serve(hub.wrap_handler(refuse), "127.0.0.1", 0)
        port = server.sockets[0].getsockname()[1]
        socket = await connect(f"ws://127.0.0.1:{port}{SOCKET_PATH}?slug=heartbeat_logger")
        await Editor(socket).expect("load", file=None)
        connected.set()
        return server, socket

    server, socket = asyncio.run_coroutine_threadsafe(serve_one_editor(), loop).result(30)
    assert connected.is_set()
    watcher = hub._watcher
    assert watcher is not None and not watcher.done()  # an editor is open: it watches

    hub.close()
    assert watcher.done() and watcher.cancelled()

    async def end() -> None:
        await socket.close()
        server.close()
        await server.wait_closed()

    asyncio.run_coroutine_threadsafe(end(), loop).result(30)
    loop.call_soon_threadsafe(loop.stop)
    thread.join(10)
    loop.close()
    del watcher
    gc.collect()
    assert "Task was destroyed" not in caplog.text
