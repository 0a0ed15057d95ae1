"""Numeric fields over time (joint angles) as a uPlot chart in the panel.

Samples are appended from a scene worker thread into a bounded buffer; the
chart's data is sent from the UI thread at most every refresh (5 Hz), so a
100 Hz joint_states topic costs the browser five small updates a second.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Sequence

import numpy as np
import viser
import viser.uplot as uplot

WINDOW_SEC = 20.0
MAX_SAMPLES = 600
MAX_SERIES = 6
_COLOURS = ("#e8590c", "#1c7ed6", "#2f9e44", "#ae3ec9", "#f08c00", "#0c8599")


class JointPlot:
    def __init__(
        self, gui: viser.GuiApi, title: str = "Joint angles (°) over the last 20 s"
    ) -> None:
        self._gui = gui
        self._title = title
        self._lock = threading.Lock()
        self._names: tuple[str, ...] = ()
        self._samples: deque[tuple[float, np.ndarray]] = deque(maxlen=MAX_SAMPLES)
        self._dirty = False
        self._t0 = time.monotonic()
        self._container = gui.add_folder("Joint plot", expand_by_default=True)
        self._handle: viser.GuiUplotHandle | None = None
        self._shown_names: tuple[str, ...] = ()

    def add(self, names: Sequence[str], values_rad: Sequence[float]) -> None:
        """Record one sample (called from a worker thread)."""
        names = tuple(names)[:MAX_SERIES]
        values = np.degrees(np.asarray(values_rad, dtype=np.float64)[: len(names)])
        with self._lock:
            if names != self._names:
                self._names = names
                self._samples.clear()
            self._samples.append((time.monotonic() - self._t0, values))
            self._dirty = True

    def clear(self) -> None:
        with self._lock:
            self._samples.clear()
            self._dirty = True

    def flush(self) -> None:
        """Send the buffered samples to the chart (UI thread)."""
        with self._lock:
            if not self._dirty:
                return
            self._dirty = False
            names = self._names
            samples = list(self._samples)
        if not names or not samples:
            return
        now = samples[-1][0]
        samples = [s for s in samples if now - s[0] <= WINDOW_SEC and len(s[1]) == len(names)]
        t = np.array([s[0] for s in samples])
        ys = np.stack([s[1] for s in samples], axis=1) if samples else np.zeros((len(names), 0))
        data = (t, *(ys[i] for i in range(len(names))))
        if self._handle is None or names != self._shown_names:
            if self._handle is not None:
                self._handle.remove()
            series = (
                uplot.Series(label="t (s)"),
                *(
                    uplot.Series(label=n, stroke=_COLOURS[i % len(_COLOURS)], width=2)
                    for i, n in enumerate(names)
                ),
            )
            with self._container:
                self._handle = self._gui.add_uplot(
                    data,
                    series,
                    title=self._title,
                    aspect=1.6,
                    scales={"x": uplot.Scale(time=False)},
                )
            self._shown_names = names
        else:
            self._handle.data = data
