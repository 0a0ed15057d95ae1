"""Benchmark: a click in the page to its effect rendered in the page, in headless Chromium.

Two interactions, each repeated: a lifecycle transition button
(``configure`` / ``cleanup`` on ``/lifecycle_talker``) until the new state is
in the page, and an ``/add_two_ints`` call from the Services form until the
response (a different sum each time) is in the page. Times are taken inside
the page: from the click event to the DOM mutation that shows the effect.

The baseline, in the same run, is the ROS round trip alone: the same
lifecycle transition and the same service call made from a plain rclpy node
in this process (no browser, no dashboard), timed from the request to the
answer.

Run: ``.venv/bin/python tests/run.py --bench click_to_effect [--repeats N]``.
The last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import re
import time
from typing import Any

from bench._common import (
    configure_dds,
    launch_browser,
    open_dashboard,
    open_tool,
    require_private_netns,
    rounded,
    start_dashboard,
    stop,
    summary,
)

# The click time (capture phase, so before React sees it) and the first DOM
# mutation after it whose page text matches the armed pattern.
CLICK_PROBE_JS = r"""
window.__clickT = null; window.__doneT = null; window.__re = null;
window.__arm = (pattern) => {
  window.__clickT = null; window.__doneT = null; window.__re = new RegExp(pattern);
};
document.addEventListener('click', () => { window.__clickT = performance.now(); }, true);
document.addEventListener('DOMContentLoaded', () => {
  new MutationObserver(() => {
    if (window.__re === null || window.__clickT === null || window.__doneT !== null) return;
    if (window.__re.test(document.body.textContent)) window.__doneT = performance.now();
  }).observe(document.body, {subtree: true, childList: true, characterData: true});
});
"""


def field(page: Any, label: str) -> Any:
    """The input next to a viser label (as tests/browser/test_ros2_panels.py finds it)."""
    text = page.get_by_text(label, exact=True).locator("visible=true").first
    return text.locator("xpath=ancestor::div[contains(@class,'mantine-Flex-root')][1]//input")


def timed_click(page: Any, button: Any, pattern: str, timeout_ms: float = 20_000) -> float:
    """Click, then wait until the page text matches ``pattern``; ms from click to render."""
    page.evaluate("p => window.__arm(p)", pattern)
    button.click()
    page.wait_for_function("window.__doneT !== null", polling=50, timeout=timeout_ms)
    return page.evaluate("window.__doneT - window.__clickT")


def start_node(page: Any, name: str) -> None:
    open_tool(page, "Nodes")
    page.get_by_label("Catalog node").click()
    page.get_by_role("option", name=name, exact=True).click()
    page.get_by_role("button", name="Start", exact=True).click()


def lifecycle_clicks(page: Any, repeats: int) -> list[float]:
    start_node(page, "lifecycle_talker")
    open_tool(page, "Lifecycle")
    initial = page.get_by_text(re.compile(r"Current state of /lifecycle_talker: unconfigured"))
    initial.first.wait_for(timeout=30_000)
    times = []
    for _ in range(repeats):
        for transition, state in (("configure", "inactive"), ("cleanup", "unconfigured")):
            button = page.get_by_role("button", name=transition, exact=True)
            page.wait_for_function(
                "b => !b.disabled", arg=button.element_handle(), polling=50, timeout=20_000
            )
            page.wait_for_timeout(300)  # let the previous answer's follow-ups settle
            times.append(
                timed_click(page, button, rf"Current state of /lifecycle_talker: {state}\b")
            )
    return times


def service_clicks(page: Any, repeats: int) -> list[float]:
    start_node(page, "add_two_ints_server")
    open_tool(page, "Services")
    deadline = time.monotonic() + 30
    while True:  # pick /add_two_ints once the dashboard lists it
        page.get_by_role("combobox", name="Service", exact=True).click()
        option = page.get_by_role("option", name="/add_two_ints", exact=True)
        if option.count():
            option.click()
            break
        if time.monotonic() > deadline:
            raise SystemExit("the Services panel never listed /add_two_ints")
        page.keyboard.press("Escape")
        page.wait_for_timeout(300)
    shown = page.get_by_text(re.compile("Type: tutorial_interfaces/srv/AddTwoInts"))
    shown.locator("visible=true").first.wait_for(timeout=30_000)
    call = page.get_by_role("button", name="Call", exact=True)
    times = []
    for k in range(repeats):
        a, b = 1000 + k, 7
        field(page, "a (int64)").fill(str(a))
        field(page, "b (int64)").fill(str(b))
        page.wait_for_timeout(300)  # the form values reach the server before the click
        times.append(timed_click(page, call, rf"AddTwoInts_Response\(sum={a + b}\)"))
    return times


def ros_baseline(repeats: int) -> tuple[list[float], list[float]]:
    """The same lifecycle transitions and service calls from a plain rclpy node."""
    import rclpy
    from lifecycle_msgs.msg import Transition
    from lifecycle_msgs.srv import ChangeState
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.signals import SignalHandlerOptions
    from tutorial_interfaces.srv import AddTwoInts

    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = Node("bench_click_baseline", context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    try:
        change = node.create_client(ChangeState, "/lifecycle_talker/change_state")
        add = node.create_client(AddTwoInts, "/add_two_ints")
        for client in (change, add):
            if not client.wait_for_service(timeout_sec=20):
                raise SystemExit(f"{client.srv_name} not available for the baseline")

        def call(client: Any, request: Any) -> float:
            t0 = time.perf_counter()
            future = client.call_async(request)
            executor.spin_until_future_complete(future, timeout_sec=10)
            if future.result() is None:
                raise SystemExit(f"no answer from {client.srv_name}")
            return (time.perf_counter() - t0) * 1000

        life, service = [], []
        for k in range(repeats):
            for transition_id in (Transition.TRANSITION_CONFIGURE, Transition.TRANSITION_CLEANUP):
                request = ChangeState.Request()
                request.transition.id = transition_id
                life.append(call(change, request))
                time.sleep(0.3)
            service.append(call(add, AddTwoInts.Request(a=k, b=1)))
            time.sleep(0.1)
        return life, service
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown(context=context)


def run(repeats: int) -> dict[str, Any]:
    from playwright.sync_api import sync_playwright

    require_private_netns("click_to_effect")
    configure_dds(20)
    dashboard, url = start_dashboard("bench-click-dashboard.log")
    try:
        with sync_playwright() as pw:
            browser = launch_browser(pw)
            page = open_dashboard(browser, url, CLICK_PROBE_JS)
            life = lifecycle_clicks(page, repeats)
            service = service_clicks(page, repeats * 2)
            # Lifecycle node back to unconfigured; both servers still up for the baseline.
            base_life, base_service = ros_baseline(repeats)
            browser.close()
    finally:
        stop(dashboard)
    ls, ss = summary(life), summary(service)
    bl, bs = summary(base_life), summary(base_service)
    both = summary(life + service)
    return {
        "repeats": len(life) + len(service),
        "lifecycle_p50_ms": ls["p50"],
        "lifecycle_p95_ms": ls["p95"],
        "service_p50_ms": ss["p50"],
        "service_p95_ms": ss["p95"],
        "click_p50_ms": both["p50"],
        "click_p95_ms": both["p95"],
        "baseline_lifecycle_p50_ms": bl["p50"],
        "baseline_service_p50_ms": bs["p50"],
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench click_to_effect")
    parser.add_argument("--repeats", type=int, default=6)
    args = parser.parse_args(argv)
    f = run(args.repeats)
    print(
        f"lifecycle click -> state shown: p50 {f['lifecycle_p50_ms']:.0f} ms, "
        f"p95 {f['lifecycle_p95_ms']:.0f} ms (plain rclpy change_state "
        f"{f['baseline_lifecycle_p50_ms']:.1f} ms)"
    )
    print(
        f"service form -> response shown: p50 {f['service_p50_ms']:.0f} ms, "
        f"p95 {f['service_p95_ms']:.0f} ms (plain rclpy call {f['baseline_service_p50_ms']:.1f} ms)"
    )
    f["aim_met"] = bool(f["click_p50_ms"] < 150)
    print(
        f"all clicks: p50 {f['click_p50_ms']:.0f} ms, p95 {f['click_p95_ms']:.0f} ms "
        "(aim p50 < 150)"
    )
    print(json.dumps(rounded(f, 1), sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
