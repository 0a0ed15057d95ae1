"""The teacher's Send empties the message box before the message leaves, never after.

Once (ci86, on a loaded machine) the two-host test's "Five minutes left" never reached a
learner. The message before it had arrived; the test then typed the next one at once, and
Send found the box empty: the teacher page's UI thread, paused between publishing a notice
and emptying the box, emptied it only after the new words had come in. Here the roster
plays that test without the machine's luck: the moment the page publishes a notice, a
second page types the next message, and the notice waits until the server holds it.

The page runs in this process as ``classroom`` builds it; its roster records what it
would publish (no DDS: what is tested is the page's order of work, not the delivery).
"""

from __future__ import annotations

from collections.abc import Callable

from app.teacher.page import TeacherPage
from app.teacher.record import LearnerRecord
from tests.conftest import free_port, wait_until
from tests.wire_client import WireClient

TOKEN = "n" * 24


class _RosterThatTypesOnPublish:
    """No learners; each notice is recorded, then ``on_publish`` runs (the UI thread)."""

    def __init__(self) -> None:
        self.sent: list[tuple[str, str]] = []
        self.on_publish: Callable[[], None] = lambda: None

    def records(self) -> list[LearnerRecord]:
        return []

    def send_notice(self, target: str, text: str) -> None:
        self.sent.append((target, text))
        self.on_publish()

    def set_reveal_after(self, value: int) -> None:
        pass


def test_a_message_typed_the_moment_the_last_one_arrives_is_sent() -> None:
    roster = _RosterThatTypesOnPublish()
    teacher = TeacherPage("127.0.0.1", free_port(), TOKEN, roster)  # type: ignore[arg-type]
    teacher.start()
    url = f"http://127.0.0.1:{teacher.port}/?token={TOKEN}"
    typist, watcher = WireClient(url), WireClient(url)
    try:
        box = wait_until(lambda: typist.find("Message"), what="the Message box")
        assert isinstance(box, str)
        wait_until(lambda: watcher.find("Message"), what="the Message box on the second page")

        def type_the_next_one() -> None:
            # The server shows a page's typing to its other pages once it holds the words.
            typist.set_value(box, "Five minutes left")
            wait_until(
                lambda: watcher.value(box) == "Five minutes left",
                what=lambda: f"the typed words on the second page: {watcher.value(box)!r}",
            )

        typist.set_value(box, "Look again at the QoS step")
        roster.on_publish = type_the_next_one
        typist.click("Send")
        wait_until(lambda: "Sent to everyone" in watcher.markdown(), what="the first Send")
        roster.on_publish = lambda: None
        assert watcher.value(box) == "Five minutes left", "Send wiped words typed after it"

        typist.click("Send")
        wait_until(
            lambda: len(roster.sent) == 2 or "⚠" in watcher.markdown(),
            what=lambda: f"the second Send: {roster.sent}",
        )
        assert roster.sent == [("", "Look again at the QoS step"), ("", "Five minutes left")], (
            roster.sent,
            watcher.markdown(),
        )
    finally:
        typist.close()
        watcher.close()
        teacher.close()
