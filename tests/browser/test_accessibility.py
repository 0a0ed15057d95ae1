"""Everyone can use the dashboard: axe-core finds no serious or critical violation in the
lesson, exercise and graph views (light and dark); at 125 % browser zoom the step's
controls stay in view; the keyboard alone moves through a lesson; in dark mode the stage
graph's colours come from the theme and stay readable.

One dashboard for the module, with talker and listener running beside it (started by
a supervisor here, as any ROS program could), so the graph has something to show.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest
from playwright.sync_api import Browser, Page, expect

from app.supervisor import Supervisor
from tests.browser.helpers import (
    NEXT_OR_SKIP,
    click,
    expect_text,
    go_to_step,
    open_page,
    open_tab,
    step_reads_top_down,
)
from tests.browser.stage_layout import stage_problem
from tests.conftest import ARTIFACTS, DashboardProcess, fail_on_leftover_nodes, free_port
from tests.course_data import shared_course
from tests.outside_report import private_dds_env

pytestmark = [pytest.mark.browser, pytest.mark.ros]

AXE = Path(__file__).parent / "axe" / "node_modules" / "axe-core" / "axe.min.js"
COURSE = shared_course()
ZOOM_125 = {"viewport": {"width": 1093, "height": 614}, "device_scale_factor": 1.25}  # 1366x768
# The steps with the most controls (buttons + answers + checks): they must fit too.
CROWDED = [("20_workspaces_packages", 9), ("21_bags", 3), ("03_turtlesim_record_launch", 7)]


@pytest.fixture(scope="module")
def dashboard_with_chatter(tmp_path_factory) -> Iterator[DashboardProcess]:
    env = private_dds_env()
    nodes = Supervisor(env)
    dashboard = DashboardProcess(
        env, free_port(), ["--progress-dir", str(tmp_path_factory.mktemp("progress"))]
    )
    try:
        nodes.start("talker")
        nodes.start("listener")
        yield dashboard
    finally:
        dashboard.stop()
        nodes.shutdown()
    fail_on_leftover_nodes("the accessibility tests")


def _page(browser: Browser, url: str, **context: object) -> Page:
    options = {"viewport": {"width": 1366, "height": 768}, **context}
    page = browser.new_context(**options).new_page()  # type: ignore[arg-type]
    open_page(page, url)
    return page


def _serious_violations(page: Page) -> list[str]:
    """axe-core's serious and critical findings on the page as it is now."""
    if not AXE.exists():
        pytest.fail(f"axe-core is missing ({AXE}): `make setup` installs it with npm ci")
    page.add_script_tag(path=str(AXE))
    found = page.evaluate(
        """async () => {
          const result = await axe.run(document, {resultTypes: ['violations']});
          return result.violations
            .filter((v) => v.impact === 'serious' || v.impact === 'critical')
            .map((v) => `${v.impact} ${v.id}: ${v.help} (${v.nodes.length}x, e.g. `
              + `${v.nodes[0].target.join(' ')}: ${v.nodes[0].failureSummary})`);
        }"""
    )
    return list(found)


def test_axe_finds_nothing_serious_in_the_lesson_exercise_and_graph_views(
    browser, dashboard_with_chatter
):
    url = dashboard_with_chatter.url
    for scheme, address in (("light", url), ("dark", url + "/?darkMode")):
        page = _page(browser, address)
        try:
            expect_text(page, "Step 1 of")  # the lesson view: text, step card, tools
            views = {"lesson": _serious_violations(page)}
            open_tab(page, "Exercise")
            click(page, "Open my code")  # the editor on stage
            expect(page.get_by_role("tab", name="Your code")).to_be_visible(timeout=20_000)
            views["exercise"] = _serious_violations(page)
            page.get_by_label("On stage").click()
            page.get_by_role("option", name="Live ROS graph", exact=True).click()
            open_tab(page, "Graph")
            expect(page.locator('svg.stage-graph g[data-name="/listener"]')).to_be_visible(
                timeout=20_000
            )
            expect_text(page, "ros2 node list")
            views["graph"] = _serious_violations(page)
            page.screenshot(path=str(ARTIFACTS / f"accessibility-{scheme}.png"))
        finally:
            page.context.close()
        problems = {view: found for view, found in views.items() if found}
        assert not problems, f"{scheme} mode: {problems}"


def test_at_125_percent_zoom_each_step_reads_top_down_and_every_control_is_reachable(
    browser, dashboard_with_chatter
):
    page = _page(browser, dashboard_with_chatter.url, **ZOOM_125)
    try:
        places = [(lesson, 0) for lesson in COURSE.lessons]
        places += [(COURSE.lesson(lesson_id), index) for lesson_id, index in CROWDED]
        hidden = []
        for lesson, index in places:
            go_to_step(page, lesson, index)
            stage = lesson.steps[index].stage or lesson.stage
            whys = [off] if (off := stage_problem(page, stage)) else []  # as at 100 %
            whys += step_reads_top_down(page, lesson, index)
            hidden += [f"{lesson.id} step {index + 1}: {why}" for why in whys]
        assert not hidden, "; ".join(hidden)
    finally:
        page.screenshot(path=str(ARTIFACTS / "accessibility-zoom-125.png"))
        page.context.close()


def _focused(page: Page) -> str:
    return page.evaluate("() => (document.activeElement.innerText || '').trim()")


def _tab_to(
    page: Page, name: str | re.Pattern[str], backwards: bool = False, limit: int = 80
) -> int:
    """Press Tab (Shift+Tab) until the button called ``name`` has the focus; how many."""
    for count in range(1, limit + 1):
        page.keyboard.press("Shift+Tab" if backwards else "Tab")
        focused = _focused(page)
        if focused == name or (isinstance(name, re.Pattern) and name.fullmatch(focused)):
            return count
    pytest.fail(f"{limit} presses of {'Shift+' if backwards else ''}Tab never reached {name!r}")


def test_the_keyboard_alone_moves_through_a_lesson(browser, dashboard_with_chatter):
    page = _page(browser, dashboard_with_chatter.url)
    try:
        lesson = COURSE.lesson("01_ros2_and_dds")
        go_to_step(page, lesson, 0)  # (the mouse only picks the lesson to start from)
        page.locator("body").click(position={"x": 5, "y": 700})  # focus on the page itself
        total = len(lesson.steps)
        _tab_to(page, NEXT_OR_SKIP)
        page.keyboard.press("Enter")
        expect_text(page, f"Step 2 of {total}: {lesson.steps[1].title}")
        _tab_to(page, "Back", backwards=True)
        page.keyboard.press("Enter")
        expect_text(page, f"Step 1 of {total}: {lesson.steps[0].title}")
        button = lesson.steps[0].actions[0]["label"]  # "Open the Nodes panel"
        _tab_to(page, button)  # (Back went disabled and gave the focus up: from the top)
        page.keyboard.press("Enter")
        expect_text(page, "Nodes is open below")
        expect(page.get_by_role("tab", name="Nodes", exact=True)).to_have_attribute(
            "aria-selected", "true"
        )
        # Focus shows where it is: the focused control draws an outline.
        _tab_to(page, NEXT_OR_SKIP)
        outline = page.evaluate("() => getComputedStyle(document.activeElement).outlineStyle")
        assert outline != "none", "the focused Next button shows no focus ring"
    finally:
        page.screenshot(path=str(ARTIFACTS / "accessibility-keyboard.png"))
        page.context.close()


_STAGE_COLOURS = """() => {
  const svg = document.querySelector('svg.stage-graph');
  const fill = (el) => getComputedStyle(el).fill;
  let box = svg;
  while (box && /rgba\\(0, 0, 0, 0\\)|transparent/.test(getComputedStyle(box).backgroundColor))
    box = box.parentElement;
  const background = box ? getComputedStyle(box).backgroundColor : 'rgb(255, 255, 255)';
  return {
    background,
    names: [...svg.querySelectorAll('g.sg-vertex')].map((g) =>
      [g.dataset.name, fill(g.querySelector('text.sg-name')), fill(g.querySelector('.sg-node,'
        + '.sg-topic,.sg-service,.sg-action'))]),
    rates: [...svg.querySelectorAll('text.sg-rate')].map(fill),
    dots: [...svg.querySelectorAll('circle.sg-dot')].map(fill),
    edges: [...svg.querySelectorAll('path.sg-edge')].map((p) => getComputedStyle(p).stroke),
  };
}"""


def _luminance(colour: str) -> float:
    r, g, b = (int(v) / 255 for v in re.findall(r"\d+", colour)[:3])
    linear = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in (r, g, b)]
    return 0.2126 * linear[0] + 0.7152 * linear[1] + 0.0722 * linear[2]


def _contrast(a: str, b: str) -> float:
    high, low = sorted((_luminance(a), _luminance(b)), reverse=True)
    return (high + 0.05) / (low + 0.05)


def _stage_colours(browser: Browser, url: str) -> dict:
    page = _page(browser, url)
    try:
        page.get_by_label("On stage").click()
        page.get_by_role("option", name="Live ROS graph", exact=True).click()
        expect(page.locator("svg.stage-graph text.sg-rate").first).to_be_visible(timeout=20_000)
        page.screenshot(path=str(ARTIFACTS / f"accessibility-stage-{url[-8:].strip('/?')}.png"))
        return page.evaluate(_STAGE_COLOURS)
    finally:
        page.context.close()


def test_in_dark_mode_the_stage_graph_takes_the_themes_colours_and_stays_readable(
    browser, dashboard_with_chatter
):
    light = _stage_colours(browser, dashboard_with_chatter.url)
    dark = _stage_colours(browser, dashboard_with_chatter.url + "/?darkMode")
    assert _luminance(dark["background"]) < 0.05 < _luminance(light["background"])
    for scheme, seen in (("light", light), ("dark", dark)):
        background = seen["background"]
        for name, text, shape in seen["names"]:  # names on their boxes: text contrast
            assert _contrast(text, shape) >= 4.5, f"{scheme}: {name} {text} on {shape}"
        for colour in seen["rates"]:  # rates written on the page's background
            assert _contrast(colour, background) >= 4.5, f"{scheme}: rate {colour}"
        for colour in seen["dots"] + seen["edges"]:  # shapes: 3:1 (WCAG 1.4.11)
            assert _contrast(colour, background) >= 3.0, f"{scheme}: {colour} on {background}"
    # The colours follow the theme rather than being fixed: the text of the boxes changed.
    assert {t for _n, t, _s in light["names"]} != {t for _n, t, _s in dark["names"]}
