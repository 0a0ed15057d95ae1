"""Bags panel: record topics, see what a bag holds, play it back, download it.

The same recorder and player as `ros2 bag record/play` (app.bags). State
lives on the UI thread: the recorder is polled from ``refresh`` (it only
looks at the graph and adds subscriptions; its writer thread does the disk
work) and a playback runs as a job on a worker thread, read through its
thread-safe ``progress``. Bags are kept in the bags folder (app.bags.folder).
"""

from __future__ import annotations

import io
import threading
import time
import zipfile
from pathlib import Path

import viser
from rclpy.node import Node

from app.bags.errors import BagError
from app.bags.folder import bags_dir, default_bag_name, list_bags
from app.bags.info import BagInfo, human_size, info_lines, read_info
from app.bags.player import Player, PlayOptions
from app.bags.recorder import Recorder, RecordingStatus
from app.panels.foxglove_section import FoxgloveSection
from app.ros.errors import Cancelled
from app.ros.graph import GraphSnapshot
from app.ui import MarkdownView, assign, code_block, set_options
from app.ui.loop import UiLoop

NONE = "(no bag yet)"
BAGS_CHECK_SEC = 2.0  # the folder is listed this often (bags made in the Console show up)
MAX_DOWNLOAD_BYTES = 200 * 1024 * 1024  # a browser download, not a backup tool


def recording_text(status: RecordingStatus) -> str:
    """Live per-topic counts, size and duration, as a small Markdown table."""
    head = (
        f"**Recording** `{status.path.name}` · {status.duration:.0f} s · "
        f"{human_size(status.size)} · {status.count} messages"
    )
    if status.failure:
        head = f"⚠️ {status.failure}"
    if not status.topics:
        return head + "\n\n_Waiting for the topics to be published…_"
    # A list, not a table: long type names wrap instead of pushing past the panel's edge.
    rows = "\n".join(
        f"- `{t.topic}` [{t.msgtype}] · {t.count} messages · {human_size(t.size)}"
        for t in status.topics
    )
    return f"{head}\n\n{rows}"


def bag_text(info: BagInfo) -> str:
    return code_block(info_lines(info))


class BagsPanel:
    calm = True  # once a second while idle (app.ui.Panel): a recording's counters
    hidden_work = True  # a recording's output is read and its failure caught, shown or not

    def __init__(
        self, gui: viser.GuiApi, ui: UiLoop, node: Node, folder: Path | None = None
    ) -> None:
        self._ui = ui
        self._node = node
        self._folder = folder or bags_dir()
        self._recorder: Recorder | None = None
        self._player: Player | None = None
        self._play_cancel = threading.Event()
        self._message = ""
        self._bags_checked = 0.0
        self._info_for: tuple[str, float] | None = None
        gui.add_markdown(
            "Record topics into a bag (a real rosbag2 folder: `metadata.yaml` + MCAP), "
            "then replay it with nobody else publishing. Same as `ros2 bag record/info/play` "
            "in the Console."
        )
        with gui.add_folder("Record"):
            self._topics = gui.add_text("Topics", "/chatter", hint="space-separated topic names")
            self._all = gui.add_checkbox("All topics (-a)", False)
            self._storage = gui.add_dropdown("Storage", ["mcap", "sqlite3"], initial_value="mcap")
            self._record = gui.add_button("Record", icon=viser.Icon.PLAYER_RECORD)
            self._stop = gui.add_button("Stop recording", icon=viser.Icon.PLAYER_STOP)
            self._stop.disabled = True
            self._live = MarkdownView(gui, "")
        with gui.add_folder("Bags"):
            self._selector = gui.add_dropdown("Bag", [NONE], initial_value=NONE)
            self._info = MarkdownView(gui, "")
            self._rate = gui.add_number("Rate", 1.0, min=0.1, max=10.0, step=0.1)
            self._loop = gui.add_checkbox("Loop", False)
            self._play = gui.add_button("Play", icon=viser.Icon.PLAYER_PLAY)
            self._pause = gui.add_button("Pause", icon=viser.Icon.PLAYER_PAUSE, disabled=True)
            self._stop_play = gui.add_button(
                "Stop playback", icon=viser.Icon.PLAYER_STOP, disabled=True
            )
            self._progress = gui.add_progress_bar(0.0)
            self._progress_text = MarkdownView(gui, "")
            self._download = gui.add_button("Download bag (.zip)", icon=viser.Icon.DOWNLOAD)
        self._result = MarkdownView(gui, "")
        self._foxglove = FoxgloveSection(gui, ui, node)
        self._record.on_click(ui.callback(self._start_recording))
        self._stop.on_click(ui.callback(self._stop_recording))
        self._play.on_click(ui.callback(self._start_playing))
        self._pause.on_click(ui.callback(self._toggle_pause))
        self._stop_play.on_click(ui.callback(lambda: self._play_cancel.set()))
        self._download.on_click(self._on_download)

    # ------------------------------------------------------------ recording

    def _start_recording(self) -> None:
        if self._recorder is not None:
            return
        topics = self._topics.value.split()
        path = self._folder / default_bag_name()
        try:
            self._folder.mkdir(parents=True, exist_ok=True)
            self._recorder = Recorder(
                self._node, path, topics, all_topics=self._all.value, storage=self._storage.value
            )
        except BagError as exc:
            self._message = f"⚠️ {exc}"
            return
        self._message = f"Recording into `{path}` — press **Stop recording** to finish."
        self._record.disabled, self._stop.disabled = True, False

    def _stop_recording(self) -> None:
        recorder, self._recorder = self._recorder, None
        if recorder is None:
            return
        self._stop.disabled = True

        def done(status: RecordingStatus) -> None:
            self._record.disabled = False
            self._live.show(recording_text(status))
            if status.failure:
                self._message = f"⚠️ {status.failure}"
            else:
                self._message = f"Saved `{status.path.name}`: {status.count} messages."
            self._refresh_bags(select=status.path.name)

        def failed(text: str) -> None:
            self._record.disabled = False
            self._message = f"⚠️ {text}"

        # Closing the bag waits for the writer thread: off the UI thread.
        self._ui.run_job(recorder.stop, done, failed)

    # ------------------------------------------------------------ playing

    def _selected(self) -> Path | None:
        """The chosen bag; only one the dropdown lists (viser does not check a dropdown's
        value, and a forged one must not reach a file outside the folder)."""
        name = self._selector.value
        if name == NONE or name not in self._selector.options:
            return None
        return self._folder / name

    def _start_playing(self) -> None:
        path = self._selected()
        if path is None or self._player is not None:
            return
        options = PlayOptions(rate=float(self._rate.value), loop=self._loop.value)
        try:
            player = Player(self._node, path, options)
        except BagError as exc:
            self._message = f"⚠️ {exc}"
            return
        self._player = player
        self._play_cancel = cancel = threading.Event()
        self._play.disabled = True
        self._pause.disabled = self._stop_play.disabled = False
        self._message = (
            f"Playing `{path.name}` at rate {options.rate:g}: {', '.join(player.topics)}"
        )

        def work() -> str:
            try:
                done = player.run(cancel)
            except Cancelled:
                return f"Stopped `{path.name}` after {player.progress().published} messages."
            return f"Played `{path.name}`: {done.published} messages."

        def finished(text: str) -> None:
            self._message = text
            self._end_playback()

        def failed(text: str) -> None:
            self._message = f"⚠️ {text}"
            self._end_playback()

        self._ui.run_job(work, finished, failed)

    def _end_playback(self) -> None:
        player, self._player = self._player, None
        if player is not None:
            assign(self._progress, 100.0 * player.progress().fraction)
            player.close()
        self._play.disabled = False
        self._pause.disabled = self._stop_play.disabled = True
        self._pause.label = "Pause"

    def _toggle_pause(self) -> None:
        player = self._player
        if player is None:
            return
        if player.paused:
            player.resume()
            self._pause.label = "Pause"
        else:
            player.pause()
            self._pause.label = "Resume"

    # ------------------------------------------------------------ download

    def _on_download(self, event: viser.GuiEvent[viser.GuiButtonHandle]) -> None:
        client = event.client
        self._ui.post(lambda: self._send_zip(client))

    def _send_zip(self, client: viser.ClientHandle | None) -> None:
        path = self._selected()
        if path is None or client is None:
            return
        files = [p for p in sorted(path.iterdir()) if p.is_file()]
        if sum(p.stat().st_size for p in files) > MAX_DOWNLOAD_BYTES:
            self._message = f"⚠️ `{path.name}` is too big to download here; copy it from {path}"
            return

        def work() -> bytes:
            buffer = io.BytesIO()
            with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
                for file in files:
                    archive.write(file, f"{path.name}/{file.name}")
            return buffer.getvalue()

        def send(content: bytes) -> None:
            client.send_file_download(f"{path.name}.zip", content, save_immediately=True)
            self._message = f"Sent `{path.name}.zip` ({human_size(len(content))})."

        self._ui.run_job(work, send, lambda text: setattr(self, "_message", f"⚠️ {text}"))

    # ------------------------------------------------------------ refresh

    def _bag_names(self) -> list[str]:
        """Finished bags, newest first (the one being recorded is not one yet)."""
        recording = self._recorder.path.name if self._recorder else None
        return [p.name for p in list_bags(self._folder) if p.name != recording] or [NONE]

    def _refresh_bags(self, select: str | None = None) -> None:
        self._bags_checked = time.monotonic()
        names = self._bag_names()
        set_options(self._selector, names, keep_current=False)
        if select in names:
            assign(self._selector, select)

    def _show_info(self) -> None:
        path = self._selected()
        if path is None:
            self._info.show("_Record something first._")
            return
        meta = path / "metadata.yaml"
        key = (path.name, meta.stat().st_mtime if meta.exists() else 0.0)
        if key == self._info_for:
            return
        self._info_for = key
        try:
            self._info.show(bag_text(read_info(path)))
        except BagError as exc:
            self._info.show(f"⚠️ {exc}")

    def refresh(self, graph: GraphSnapshot) -> None:
        if time.monotonic() - self._bags_checked > BAGS_CHECK_SEC:
            self._refresh_bags()
        self._show_info()
        recorder = self._recorder
        if recorder is not None:
            lines = recorder.poll()
            warnings = [line for line in lines if line.startswith("[WARN]")]
            if warnings:
                self._message = "⚠️ " + warnings[-1].removeprefix("[WARN] ")
            status = recorder.status()
            self._live.show(recording_text(status))
            if status.failure:
                self._stop_recording()
        player = self._player
        if player is not None:
            progress = player.progress()
            assign(self._progress, round(100.0 * progress.fraction, 1))
            state = "paused" if progress.paused else "playing"
            passes = f" · pass {progress.loops + 1}" if self._loop.value else ""
            self._progress_text.show(
                f"{state}: {progress.position:.1f} s of {progress.duration:.1f} s · "
                f"{progress.published} messages{passes}"
            )
        self._result.show(self._message)
        self._foxglove.refresh(graph)

    def close(self) -> None:
        self._foxglove.close()
        self._play_cancel.set()
        if self._recorder is not None:
            self._recorder.stop()
            self._recorder = None
