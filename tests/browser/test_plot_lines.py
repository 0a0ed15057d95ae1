"""A line added to the plot stage's chart never freezes it, however the page gets the update.

viser sends a chart's lines (``series``) and its data as two messages. On a
loaded machine the page can draw them apart (ci34: the executors lesson's rate
chart stayed 157 px wide for good when its second topic came). A chart drawn
with more lines than data arrays throws inside uPlot's first draw and from then
on ignores every resize and update. Here every property the stage sets reaches
the page on its own and is drawn before the next: the worst order the wire can
give. The chart must still fill its box with both lines, and the page log no
error.
"""

from __future__ import annotations

import time
from typing import Any

import pytest
import viser

from app.access import make_server
from app.stage.plot_stage import History, _draw
from tests.conftest import free_port, wait_until

pytestmark = [pytest.mark.browser]

DRAWN_SEC = 0.5  # time for the page to draw one message before the next is sent


class OneMessageAtATime:
    """A chart handle whose every assignment is sent at once and drawn before the next."""

    def __init__(self, chart: viser.GuiUplotHandle, server: viser.ViserServer) -> None:
        object.__setattr__(self, "_chart", chart)
        object.__setattr__(self, "_server", server)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._chart, name)

    def __setattr__(self, name: str, value: Any) -> None:
        setattr(self._chart, name, value)
        self._server.flush()
        time.sleep(DRAWN_SEC)


def _history(names: tuple[str, ...], samples: int) -> History:
    history = History()
    for k in range(samples):
        history.add(float(k), {name: 1.0 + i + 0.1 * k for i, name in enumerate(names)})
    return history


def _chart_box(page: Any) -> dict[str, float]:
    return page.evaluate(
        """() => {
          const canvas = document.querySelector('.uplot canvas');
          const paper = document.querySelector('.uplot-container');
          if (!canvas || !paper) return {canvas: 0, paper: 0};
          return {canvas: canvas.getBoundingClientRect().width,
                  paper: paper.getBoundingClientRect().width};
        }"""
    )


def test_a_second_line_arriving_apart_from_its_data_leaves_the_chart_whole(browser):
    server, _ = make_server("127.0.0.1", free_port(), None)  # as the dashboard makes its own
    context = browser.new_context(viewport={"width": 1366, "height": 768})
    errors: list[str] = []
    try:
        page = context.new_page()
        page.on("pageerror", lambda error: errors.append(str(error)))
        page.goto(f"http://127.0.0.1:{server.get_port()}")
        chart = server.gui.add_uplot(
            _history(("/one",), 3).data(),
            (viser.uplot.Series(label="seconds ago"), viser.uplot.Series(label="/one")),
            title="Messages a second (Hz)",
            height=230,
        )
        wait_until(lambda: _chart_box(page)["canvas"] > 0, timeout=30, what="the chart drawn")
        split = OneMessageAtATime(chart, server)
        _draw(split, _history(("/one", "/two"), 4))  # type: ignore[arg-type]
        _draw(split, _history(("/one", "/two"), 5))  # type: ignore[arg-type]

        def fills() -> bool:
            box = _chart_box(page)
            return box["canvas"] > 0.7 * box["paper"] > 0

        wait_until(fills, timeout=10, what=lambda: f"the chart to fill its box: {_chart_box(page)}")
        assert not errors, errors
        legend = page.locator(".uplot .u-legend").inner_text()
        assert "/one" in legend and "/two" in legend, legend
    finally:
        context.close()
        server.stop()
