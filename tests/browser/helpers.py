"""Selectors that work on viser's page (see DESIGN.md section 6)."""

from __future__ import annotations

import re
import time
from collections.abc import Callable
from typing import Any

import pytest
from playwright.sync_api import Locator, Page, expect
from playwright.sync_api import TimeoutError as PlaywrightTimeout

from app.lessons.panel import COURSE_END, action_button_label, answer_button_label
from bench._common import open_tool
from tests.wire_client import NEXT_OR_SKIP

# A tool's tab opened as a learner does: its group's tab first (Inspect, then Echo).
open_tab = open_tool

# A fresh page parses viser's bundle and has the whole GUI replayed over its
# websocket before any control exists. On a 2-core machine at load 12 that took
# more than Playwright's 30 s default (CI of 8a4ebc1: the Bags panel's Record
# button never came), so a page's first sight has its own wait, and the test's
# own waits count from a page that is there.
FIRST_LOAD_MS = 90_000


def open_page(page: Page, url: str, role: str = "tab", name: str = "Learn") -> Page:
    """Go to ``url`` and wait until the control ``role`` ``name`` is on the page."""
    page.goto(url, timeout=FIRST_LOAD_MS)
    page.get_by_role(role, name=name, exact=True).first.wait_for(timeout=FIRST_LOAD_MS)
    return page


def choose(page: Page, label: str, option: str) -> None:
    """Pick ``option`` in the dropdown ``label``, as a learner does: when the list closed
    before the click (the step card re-rendered under it; CI: a quiz of lesson 18),
    open it again."""
    choose_when_listed(page, label, option)


def choose_when_listed(
    page: Page, label: str, option: str, timeout: float = 30.0, exact: bool = False
) -> None:
    """Pick a dropdown option that may be listed only once discovery has found it, or
    whose list closed before the click: the list is opened again until it is picked."""
    dropdown = page.get_by_label(label, exact=exact).locator("visible=true").first
    wanted = page.get_by_role("option", name=option, exact=True)
    deadline = time.monotonic() + timeout
    while True:
        dropdown.click()
        # First the list, however long the page takes to draw it: closed unseen, a list
        # slower than the wait for the option was opened and closed for ever (CI: the
        # stage's fixed list, on a page sharing 2 cores with 3 others and the world).
        if not _list_opened(page):
            if time.monotonic() > deadline:
                pytest.fail(f"the list of {label!r} never opened")
            continue  # the click was lost (the dropdown re-rendered under it): again
        try:
            wanted.wait_for(timeout=1_500)
            # The list is sent again when discovery finds another topic: an option seen
            # a moment ago may be gone with the list it was in. Then open it again.
            wanted.click(timeout=10_000)
            if _closed(wanted) or dropdown.input_value() == option:
                return
            # A click on a list that was being replaced can land on nothing (ci21: the
            # list stayed open on "(pick a topic)"): close it and pick again. (A pick
            # closes the list; some dropdowns go back to a placeholder after one.)
            page.keyboard.press("Escape")
            if time.monotonic() > deadline:
                pytest.fail(f"picking {option!r} in {label!r} never took")
            continue
        except PlaywrightTimeout:
            if dropdown.input_value() == option:
                return  # chosen; the click's wait for what followed it timed out
            page.keyboard.press("Escape")  # not listed yet: close, let the panel refresh
            if time.monotonic() > deadline:
                pytest.fail(f"option {option!r} never appeared in {label!r}")
            page.wait_for_timeout(500)


# A list opens in 0.01-0.15 s; the stage's took 1.1 s on a page of four beside the camera,
# arm and world with one core kept busy (measured), and more in CI's full suite.
LIST_OPEN_MS = 10_000


def _list_opened(page: Page) -> bool:
    """Whether a dropdown's list is shown within LIST_OPEN_MS of the click."""
    try:
        page.get_by_role("listbox").locator("visible=true").first.wait_for(timeout=LIST_OPEN_MS)
        return True
    except PlaywrightTimeout:
        return False


def _closed(option_locator, timeout_ms: float = 3_000) -> bool:
    """Whether the list holding this option closes within ``timeout_ms`` (a pick closes it)."""
    try:
        option_locator.wait_for(state="hidden", timeout=timeout_ms)
        return True
    except PlaywrightTimeout:
        return False


def open_lesson(page: Page, lesson) -> None:
    """Pick ``lesson`` in Learn › Lessons, as a learner does (another tool may be open);
    nothing when it is the lesson on screen (picking it again changes nothing)."""
    label = f"{lesson.unit:02d} · {lesson.title}"
    dropdown = page.get_by_label("Lesson", exact=True)
    if dropdown.count() == 1 and dropdown.input_value() == label:
        return
    open_tab(page, "Lessons")
    choose(page, "Lesson", label)


def go_to_step(page: Page, lesson, index: int) -> None:
    """Open ``lesson`` and press Next until step ``index`` (from 0) is on screen."""
    open_lesson(page, lesson)
    for at in range(index):
        expect_text(page, f"Step {at + 1} of {len(lesson.steps)}")
        # Next once the card has settled: a step that changes the stage re-mounts the
        # column, which slides into place, and a click on the sliding card was lost (CI).
        step_head_in_view(page, lesson, at)
        click_next(page)
    expect_text(page, f"Step {index + 1} of {len(lesson.steps)}")


def click(page: Page, button: str) -> None:
    page.get_by_role("button", name=button, exact=True).click()


# A folder's contents slide open (viser's folders are Mantine Collapses, about 200 ms), and
# while they do, the panel's scroll range grows and the buttons inside can still move:
# Playwright's own check (the same box on two animation frames) passes on a slow machine.
# cb18c3d's CI, Open in Foxglove: pressed at y 684, released 3 ms later with the button at
# 712, and the click went to the paragraph above. Measured here at a 760 px high window, a
# click straight after opening: the panel scrolled to the button mid-slide, and the button
# then moved from y 693 to 712. Settled = the folder's box and its scroll area's height and
# position the same for 300 ms.
_FOLDER_SETTLED = """(folder) => {
  let box = folder; while (box && getComputedStyle(box).overflowY === 'visible')
    box = box.parentElement;
  const r = folder.getBoundingClientRect();
  const now = `${r.y} ${r.height} ${box ? box.scrollHeight + ' ' + box.scrollTop : ''}`;
  const t = performance.now();
  if (folder.__seen !== now) { folder.__seen = now; folder.__since = t; }
  return t - folder.__since >= 300;
}"""


def open_folder(page: Page, label: str) -> None:
    """Open the folder titled ``label`` (visible, closed) and wait until it has slid open."""
    header = page.get_by_text(label, exact=True).filter(visible=True).first
    header.click()
    folder = header.evaluate_handle("(h) => h.parentElement")
    page.wait_for_function(_FOLDER_SETTLED, arg=folder, polling=50, timeout=10_000)


# Records where a click's press and release landed, and where the button was then: a click
# that did nothing says whether it moved under the pointer, landed elsewhere, or never
# reached the page (ci102 lost "Publish at rate": a wrong, longer Rate line above it had
# wrapped, app/ros/monitor.py).
_CLICK_RECORDER = """(name) => {
  const found = () => [...document.querySelectorAll('button')]
    .find(b => b.textContent.trim() === name);
  const rect = (el) => { if (!el) return 'gone';
    const r = el.getBoundingClientRect();
    return `${Math.round(r.x)},${Math.round(r.y)} ${Math.round(r.width)}x${Math.round(r.height)}`
      + (el.disabled ? ' disabled' : ''); };
  window.__clicks = [];
  for (const type of ['pointerdown', 'pointerup', 'click']) {
    document.addEventListener(type, (e) => window.__clicks.push(
      `${type} at ${Math.round(e.clientX)},${Math.round(e.clientY)} on `
      + `${e.target.tagName} '${(e.target.textContent || '').trim().slice(0, 30)}'; `
      + `button ${rect(found())}, t=${Math.round(performance.now())}`), true);
  }
}"""


def watched_click(page: Page, button: str) -> Callable[[], str]:
    """Click ``button``; a function that says what the page saw of that click."""
    page.evaluate(_CLICK_RECORDER, button)
    click(page, button)
    return lambda: "; ".join(page.evaluate("window.__clicks || []")) or "no event at all"


def click_next(page: Page) -> None:
    """Press the step card's Next, whichever of its two labels it shows now."""
    page.get_by_role("button", name=NEXT_OR_SKIP).click()


def start_node(page: Page, name: str) -> None:
    """Start one catalog node from the Nodes tab, as a learner does."""
    open_tab(page, "Nodes")
    choose(page, "Catalog node", name)
    click(page, "Start")
    expect_text(page, f"Started {name}")


def start_group(page: Page, group: str) -> None:
    """Start a launch group from the Nodes tab."""
    open_tab(page, "Nodes")
    choose(page, "Launch group", group)
    click(page, "Start group")
    expect_text(page, "Started group")


# The code editor (app/exercises/editor) is read-only until the learner's saved code has
# arrived, and only then: taking typing is the sign it is loaded. Its status says
# "connected" before that, and text put in then is replaced by the saved code (ci17: the
# kill/restart test's round 4 set its code in that moment, and the saved code won).
EDITOR_TAKES_TYPING = "textarea.ace_text-input:not([readonly])"


def expect_editor_loaded(editor: Any, timeout: float = 30_000) -> None:
    """``editor`` (the editor's frame locator) shows the saved code and takes typing."""
    expect(editor.locator(EDITOR_TAKES_TYPING)).to_be_attached(timeout=timeout)


def expect_text(page: Page, text: str | re.Pattern[str], timeout: float = 20_000) -> None:
    """``text`` is on screen: hidden copies (other tabs, closed folders) do not count."""
    expect(page.get_by_text(text).filter(visible=True).first).to_be_visible(timeout=timeout)


# Elements of the control panel that stick out past its right edge (clipped text).
_CUT_OFF_JS = """([selector, text]) => {
  let panel = [...document.querySelectorAll(selector)].find((e) => e.innerText.trim() === text);
  const scrolls = (el) => ['auto', 'scroll'].includes(getComputedStyle(el).overflowY);
  while (panel && !scrolls(panel)) panel = panel.parentElement;
  if (!panel) return ['no scrolling control panel found'];
  const edge = panel.getBoundingClientRect().right;
  const out = [];
  for (const el of panel.querySelectorAll('*')) {
    const box = el.getBoundingClientRect();
    if (!box.width || !box.height || getComputedStyle(el).visibility === 'hidden') continue;
    if (box.right > edge + 1) {
      const text = (el.innerText || el.textContent || '').trim().slice(0, 40);
      out.push(`${el.tagName} "${text}" ends at ${Math.round(box.right)} > ${Math.round(edge)}`);
    }
  }
  return out.slice(0, 8);
}"""


def cut_off_at_panel_edge(page: Page, selector: str, text: str) -> list[str]:
    """What sticks out of the scrolling panel that holds ``selector`` with ``text`` (none: [])."""
    return page.evaluate(_CUT_OFF_JS, [selector, text])


# Why an element is not fully in view: outside the window, clipped by a scrolling box
# (the control panel scrolled), or covered by something else; '' when the learner sees it.
_WHY_UNSEEN_FN = """function whyUnseen(el, scroll) {
  if (scroll) el.scrollIntoView({block: 'nearest'});
  const r = el.getBoundingClientRect();
  const at = (b) => `${Math.round(b.top)}..${Math.round(b.bottom)} x ${Math.round(b.left)}..`
    + `${Math.round(b.right)}`;
  if (!r.width || !r.height) return 'not shown';
  if (r.top < -0.5 || r.left < -0.5 || r.bottom > innerHeight + 0.5 || r.right > innerWidth + 0.5)
    return `outside the ${innerWidth}x${innerHeight} window at ${at(r)}`;
  for (let box = el.parentElement; box; box = box.parentElement) {
    const style = getComputedStyle(box);
    if (!/(auto|scroll|hidden|clip)/.test(style.overflowX + style.overflowY)) continue;
    const b = box.getBoundingClientRect();
    if (r.top < b.top - 0.5 || r.bottom > b.bottom + 0.5 || r.left < b.left - 0.5
        || r.right > b.right + 0.5)
      return `at ${at(r)}, cut off by a scrolling box at ${at(b)}`;
  }
  const hit = document.elementFromPoint(r.left + r.width / 2, r.top + r.height / 2);
  if (!hit || !(hit === el || el.contains(hit) || hit.contains(el)))
    return `covered by ${hit ? hit.tagName + ' ' + (hit.innerText || '').slice(0, 30) : 'nothing'}`;
  return '';
}"""

_OUT_OF_VIEW_JS = (
    "([elements, scroll]) => { "
    + _WHY_UNSEEN_FN
    + " return elements.map((el) => whyUnseen(el, scroll)); }"
)


def out_of_view(page: Page, controls: dict[str, Locator], scroll: bool = False) -> list[str]:
    """Each control (name -> locator) the learner cannot see whole without scrolling
    (``scroll``: once scrolled to, as a learner reading down the column does).

    Waits for each to be on the page (up to 10 s), then looks at all of them at once.
    """
    handles = [locator.first.element_handle(timeout=10_000) for locator in controls.values()]
    reasons = page.evaluate(_OUT_OF_VIEW_JS, [handles, scroll])
    return [f"{name}: {why}" for name, why in zip(controls, reasons, strict=True) if why]


# A step card's controls found as the Playwright locators of ``step_controls`` find them,
# in one pass over the page (those locators cost about 0.4 s a step on a loaded machine,
# 171 steps a walk): text as get_by_text (spaces folded; the innermost element holding
# it; exact, or any case), buttons as get_by_role("button", name=..., exact) (the name
# is aria-label or the text; hidden ones left out), check lines as li elements whose text
# matches CHECK_LINE. Answers a list of what is missing, or the named elements.
_STEP_CARD_FN = """function stepCard(spec) {
  const fold = (s) => (s || '').replace(/\\s+/g, ' ').trim();
  const visible = (e) => { const r = e.getBoundingClientRect();
    return r.width > 0 && r.height > 0 && getComputedStyle(e).visibility !== 'hidden'; };
  const inTree = (e) => e.getClientRects().length > 0 && !e.closest('[aria-hidden=true]')
    && getComputedStyle(e).visibility !== 'hidden';
  const everything = [...document.body.querySelectorAll('*')]
    .filter((e) => !['SCRIPT', 'STYLE'].includes(e.tagName));
  const innermost = (test) => {
    const hits = new Set(everything.filter((e) => test(fold(e.textContent))));
    return [...hits].filter((e) => ![...e.children].some((c) => hits.has(c)));
  };
  const buttons = [...document.body.querySelectorAll(
    'button, [role=button], input[type=button], input[type=submit]')].filter(inTree);
  const nameOf = (b) => fold(b.getAttribute('aria-label') || b.innerText || b.value || '');
  const button = (test) => buttons.find((b) => test(nameOf(b)));
  const found = {}, missing = [];
  const want = (name, el) => { if (el) found[name] = el; else missing.push(name); };
  want('title', innermost((t) => t === spec.title)[0]);
  const words = spec.words.toLowerCase();
  want('text', innermost((t) => t.toLowerCase().includes(words)).find(visible));
  if (spec.head) return {missing, names: Object.keys(found), elements: Object.values(found)};
  for (const [name, label] of spec.buttons) want(name, button((n) => n === label));
  const line = new RegExp(spec.check_line);
  const shared = new RegExp(spec.shared_line);  // one line for N checks waiting on one thing
  const checks = [...document.body.querySelectorAll('li')]
    .filter((e) => line.test(fold(e.textContent)) && visible(e))
    .flatMap((e) => { const m = fold(e.textContent).match(shared);
      return Array(m ? Number(m[1]) : 1).fill(e); });
  if (checks.length !== spec.checks.length)
    missing.push(`${spec.checks.length} checks on their lines (${checks.length} shown)`);
  spec.checks.forEach(([name, answers], i) => {
    for (const [answer, labels] of answers) want(answer, button((n) => labels.includes(n)));
    want(name, checks[i]);
  });
  want('Back', button((n) => n === 'Back'));
  const next = new RegExp(spec.next);
  want('Next', button((n) => next.test(n) || n === spec.end));
  return {missing, names: Object.keys(found), elements: Object.values(found)};
}"""

_STEP_CARD_JS = (
    "(spec) => { "
    + _STEP_CARD_FN
    + " "
    + _WHY_UNSEEN_FN
    + """
  const card = stepCard(spec);
  if (card.missing.length) return {missing: card.missing};
  const top = (name) => card.elements[card.names.indexOf(name)].getBoundingClientRect().y;
  const before = card.names.find((n) => n.startsWith('button') || n.startsWith('answer'));
  const order = before && top(before) < top('text')
    ? [`${before} comes before the step's text`] : [];
  const why = card.elements.map((el) => whyUnseen(el, !spec.head));
  return {missing: [], wrong: order.concat(
    card.names.map((name, i) => why[i] ? `${name}: ${why[i]}` : '').filter(Boolean))};
}"""
)


def _card_spec(lesson, index: int, head: bool) -> dict:
    """What step ``index``'s card must show, for ``_STEP_CARD_JS``."""
    step = lesson.steps[index]
    buttons = []
    for action in step.actions:
        label = action_button_label(action)
        buttons.append([f"button {label!r}", label])
    checks = []
    for i, check in enumerate(step.checks):
        answers = []
        if check.kind == "quiz":
            for option in check["options"]:
                labels = [answer_button_label(option, chosen) for chosen in (False, True)]
                answers.append([f"answer {option[:30]!r}", labels])
        checks.append([f"check {i + 1}", answers])
    return {
        "head": head,
        "title": f"Step {index + 1} of {len(lesson.steps)}: {step.title}",
        "words": first_words(step.text),
        "buttons": buttons,
        "checks": checks,
        "check_line": CHECK_LINE.pattern,
        "shared_line": SHARED_LINE.pattern,
        "next": NEXT_OR_SKIP.pattern,
        "end": COURSE_END,
    }


class CardMissing(AssertionError):
    """Part of a step card never came on the page (as a locator's wait timing out)."""


def _read_card(page: Page, lesson, index: int, head: bool, timeout: float = 10.0) -> list[str]:
    """Problems of step ``index``'s card (see ``_STEP_CARD_JS``), once all of it is on the
    page (up to ``timeout`` s, as ``step_controls``' waits); raises CardMissing after that."""
    spec = _card_spec(lesson, index, head)
    deadline = time.monotonic() + timeout
    while True:
        seen = page.evaluate(_STEP_CARD_JS, spec)
        if not seen["missing"]:
            return list(seen["wrong"])
        if time.monotonic() > deadline:
            raise CardMissing(
                f"{lesson.id} step {index + 1}: not on the page after {timeout:.0f} s: "
                + ", ".join(seen["missing"])
            )
        page.wait_for_timeout(100)


def step_reads_top_down(page: Page, lesson, index: int) -> list[str]:
    """What is wrong with step ``index``'s card as a learner reads it (none: []): its title
    and text in view as the step opens, the text above its first button and answer, and
    every control whole, uncovered and inside the window once scrolled to."""
    wrong = step_head_in_view(page, lesson, index)
    return wrong + _read_card(page, lesson, index, head=False)


def step_head_in_view(page: Page, lesson, index: int) -> list[str]:
    """What keeps a learner from reading step ``index``'s title and the start of its text
    as the step opens (none: [])."""
    # A stage change re-mounts the column (3D scene: docked right) and its panel slides
    # into place (seen: the title 20 px wide at x -287 mid-slide): a learner reads the
    # card once it has settled, so the head is judged after up to 5 s of settling.
    for _ in range(10):
        wrong = _read_card(page, lesson, index, head=True)
        if not wrong:
            break
        page.wait_for_timeout(500)
    return wrong


def first_words(markdown: str, count: int = 5) -> str:
    """The first words of a step's text as the page shows them (no title, no markup)."""
    body = [p for p in markdown.split("\n\n") if p.strip()[:1].isalpha()]  # prose
    plain = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", body[0] if body else "")
    plain = re.sub(r"[*`]|(?<!\w)_|_(?!\w)", "", plain)  # emphasis, not snake_case
    return " ".join(plain.split()[:count])


CHECK_LINE = re.compile(r"^(✓|○|…) (pass|to do|waiting)")
# Checks that wait on the same thing share a line that counts them (app/lessons/panel.py).
SHARED_LINE = re.compile(r"^\S+ (?:pass|to do|waiting) \((\d+) checks\):")
# For each visible check line, how many checks it stands for (1, or N on a shared line).
_CHECKS_PER_LINE_JS = r"""([line, shared]) => [...document.body.querySelectorAll('li')]
  .filter((e) => e.getClientRects().length > 0 && getComputedStyle(e).visibility !== 'hidden')
  .map((e) => (e.textContent || '').replace(/\s+/g, ' ').trim())
  .filter((text) => new RegExp(line).test(text))
  .map((text) => { const m = text.match(new RegExp(shared)); return m ? Number(m[1]) : 1; })"""


def step_controls(page: Page, lesson, index: int) -> dict[str, Locator]:
    """What a learner needs of step ``index`` of ``lesson`` (its title, buttons, quiz
    answers, check lines, Back and Next), by name; waits for the title and for as many
    check lines as the step has (``out_of_view`` waits for the rest)."""
    step = lesson.steps[index]
    title = f"Step {index + 1} of {len(lesson.steps)}: {step.title}"
    controls = {"title": page.get_by_text(title, exact=True)}
    expect(controls["title"]).to_be_visible()
    controls["text"] = page.get_by_text(first_words(step.text)).filter(visible=True)
    for action in step.actions:
        label = action_button_label(action)
        controls[f"button {label!r}"] = page.get_by_role("button", name=label, exact=True)
    checks = page.locator("li").filter(has_text=CHECK_LINE).filter(visible=True)
    line_of = _line_of_each_check(page, len(step.checks))
    for i, check in enumerate(step.checks):
        if check.kind == "quiz":
            for option in check["options"]:
                controls[f"answer {option[:30]!r}"] = answer_button(page, option)
        controls[f"check {i + 1}"] = checks.nth(line_of[i])
    controls["Back"] = page.get_by_role("button", name="Back", exact=True)
    last = page.get_by_role("button", name=COURSE_END, exact=True)  # the course's last step
    controls["Next"] = page.get_by_role("button", name=NEXT_OR_SKIP).or_(last)
    return controls


def _line_of_each_check(page: Page, checks: int, timeout: float = 10.0) -> list[int]:
    """Waits until the check lines stand for ``checks`` checks; the line of each."""
    deadline = time.monotonic() + timeout
    while True:
        per_line = page.evaluate(_CHECKS_PER_LINE_JS, [CHECK_LINE.pattern, SHARED_LINE.pattern])
        if sum(per_line) == checks or time.monotonic() > deadline:
            break
        time.sleep(0.1)
    assert sum(per_line) == checks, f"{checks} checks on their lines, {per_line} shown"
    return [line for line, count in enumerate(per_line) for _ in range(count)]


def answer_button(page: Page, option: str) -> Locator:
    """A quiz answer's button (its radio mark chosen or not)."""

    def button(chosen: bool) -> Locator:
        label = answer_button_label(option, chosen)
        return page.get_by_role("button", name=label, exact=True)

    return button(False).or_(button(True))


def answer_quiz(page: Page, check) -> None:
    """Click a quiz's right answer, as a learner does, and see it marked chosen."""
    answer_button(page, check["answer"]).click()
    chosen = answer_button_label(check["answer"], chosen=True)
    expect(page.get_by_role("button", name=chosen, exact=True)).to_be_visible()
