"""Helpers for the 3D-view smoke tests: synthetic publishers and scene-node queries."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from playwright.sync_api import Page

# How many points (or vertices) the scene node ``name`` or its children hold; 0 if absent.
POINT_COUNT_JS = """(name) => {
  const obj = window.__viserMutable && window.__viserMutable.nodeRefFromName[name];
  if (!obj) return 0;
  let n = 0;
  obj.traverse((c) => {
    const pos = c.geometry && c.geometry.attributes && c.geometry.attributes.position;
    if (pos && c.isPoints) n = Math.max(n, pos.count);
  });
  return n;
}"""

# World position of scene node ``name`` as [x, y, z], or null.
WORLD_POSITION_JS = """(name) => {
  const obj = window.__viserMutable && window.__viserMutable.nodeRefFromName[name];
  if (!obj) return null;
  obj.updateWorldMatrix(true, false);
  const e = obj.matrixWorld.elements;
  return [e[12], e[13], e[14]];
}"""


def scene_points(page: Page, name: str) -> int:
    return int(page.evaluate(POINT_COUNT_JS, name))


def wait_scene_points(page: Page, name: str, at_least: int, timeout_ms: float = 30_000) -> int:
    page.wait_for_function(
        f"(name) => ({POINT_COUNT_JS})(name) >= {at_least}",
        arg=name,
        polling=100,
        timeout=timeout_ms,
    )
    return scene_points(page, name)


def world_position(page: Page, name: str) -> list[float] | None:
    return page.evaluate(WORLD_POSITION_JS, name)


class Repeater:
    """Publish ``make()`` on a publisher every ``period`` seconds from a thread (test side)."""

    def __init__(self, publisher: Any, make: Callable[[int], Any], period: float) -> None:
        self._publisher = publisher
        self._make = make
        self._period = period
        self._stop = threading.Event()
        self.count = 0
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            self._publisher.publish(self._make(self.count))
            self.count += 1
            self._stop.wait(self._period)

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)


def synthetic_cloud_points(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A coloured sphere shell: easy to recognise in a screenshot."""
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(n, 3)).astype(np.float32)
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    pts = v * 0.2 + np.array([0.1, 0.6, 0.3], dtype=np.float32)
    colours = ((v * 0.5 + 0.5) * 255).astype(np.uint8)
    return pts, colours


def now_stamp() -> tuple[int, int]:
    t = time.time()
    return int(t), int((t % 1) * 1e9)
