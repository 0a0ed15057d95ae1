"""Draws what a probe judged (``app.exercises.trace.Trace``) as a picture.

One drawing for every reader: the exercise panel shows it under the result,
``exercise check`` prints the path of its PNG file, and the attempt's folder
keeps it beside the bag (the teacher looks at the same picture). matplotlib
draws off-screen (its Agg canvas, no pyplot and no display), one figure per
call, so any thread may draw; it is imported on the first plot, never at
start-up.
"""

from __future__ import annotations

import io
import re
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from app.exercises.trace import Trace

if TYPE_CHECKING:
    import numpy as np
    from matplotlib.figure import Figure

WIDTH_IN, HEIGHT_IN, DPI = 5.2, 2.6, 100  # 520 x 260 px: the panel's width, readable on paper
LINE = "#1f6fb2"
ALLOWED = "#2e9d4c"
BROKEN = "#c62828"
NOT_JUDGED = "#9e9e9e"
EXPECTED = "#fab005"


def _figure(trace: Trace) -> Figure:
    from matplotlib.figure import Figure

    figure = Figure(figsize=(WIDTH_IN, HEIGHT_IN), dpi=DPI, layout="constrained")
    axes = figure.add_subplot()
    axes.set_title(trace.title, fontsize=10, loc="left")
    axes.set_xlabel(trace.along, fontsize=8)
    axes.set_ylabel(trace.unit, fontsize=8)
    axes.tick_params(labelsize=8)
    axes.grid(True, color="#e0e0e0", linewidth=0.6)
    if not trace.values:
        axes.text(0.5, 0.5, "no values were measured", ha="center", transform=axes.transAxes)
        return figure
    times, values = trace.times, trace.values
    steps = "steps-post" if trace.levels else "default"  # a state holds until the next
    if trace.expected:
        axes.plot(
            times,
            trace.expected,
            color=EXPECTED,
            linewidth=4,
            alpha=0.5,
            drawstyle=steps,
            label="expected",
        )
    dots = "o" if len(times) < 30 else None
    axes.plot(times, values, color=LINE, linewidth=1.6, marker=dots, drawstyle=steps, label="got")
    if trace.levels:
        axes.set_yticks(range(len(trace.levels)), trace.levels)
    if trace.expected:
        axes.legend(fontsize=7, loc="lower right")
    bounds = [b for b in (trace.low, trace.high) if b is not None]
    span = [*values, *bounds, *trace.expected]
    pad = (max(span) - min(span)) * 0.12 or 0.5
    bottom, top = min(span) - pad, max(span) + pad
    axes.set_ylim(bottom, top)
    start, end = min(times), max(times)
    if end <= start:
        end = start + 1.0
    axes.set_xlim(start, end + (end - start) * 0.04)  # room for a mark at the very end
    if bounds:
        low = trace.low if trace.low is not None else bottom
        high = trace.high if trace.high is not None else top
        axes.axhspan(low, high, color=ALLOWED, alpha=0.13, linewidth=0, label="allowed")
        for bound in bounds:
            axes.axhline(bound, color=ALLOWED, linewidth=1.0, linestyle="--")
        # Words, not only a colour, say which side of a line is right.
        where, va = (low, "bottom") if trace.low is not None else (high, "top")
        axes.text(start, where, " allowed", color=ALLOWED, fontsize=8, ha="left", va=va)
    if trace.judged_from > start:
        axes.axvspan(start, trace.judged_from, color=NOT_JUDGED, alpha=0.18, linewidth=0)
        axes.text(
            (start + trace.judged_from) / 2, top, "not judged", fontsize=7, ha="center", va="top"
        )
    if trace.broken_at is not None:
        axes.axvline(trace.broken_at, color=BROKEN, linewidth=1.4)
        value = _value_at(trace, trace.broken_at)
        if value is not None:
            axes.plot([trace.broken_at], [value], "o", color=BROKEN, markersize=6)
        label = trace.broken_why or "broken here"
        right_half = trace.broken_at > (start + end) / 2
        axes.annotate(
            f" {label} ",
            (trace.broken_at, top),
            xytext=(-4 if right_half else 4, -4),
            textcoords="offset points",
            ha="right" if right_half else "left",
            va="top",
            fontsize=8,
            color=BROKEN,
            bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": BROKEN, "lw": 0.8},
        )
    return figure


def _value_at(trace: Trace, moment: float) -> float | None:
    """The value measured nearest to ``moment``."""
    if not trace.times:
        return None
    nearest = min(range(len(trace.times)), key=lambda i: abs(trace.times[i] - moment))
    return trace.values[nearest]


def png(trace: Trace) -> bytes:
    """The plot of ``trace`` as a PNG file's bytes."""
    buffer = io.BytesIO()
    _figure(trace).savefig(buffer, format="png")
    return buffer.getvalue()


def pixels(trace: Trace) -> np.ndarray:
    """The plot of ``trace`` as an RGBA image (height x width x 4, uint8): what viser shows
    (four channels: viser sends it as PNG, sharp lines, not as JPEG)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    figure = _figure(trace)
    canvas = FigureCanvasAgg(figure)
    canvas.draw()
    import numpy

    return numpy.asarray(canvas.buffer_rgba()).copy()


def file_name(index: int, trace: Trace) -> str:
    """``plot-1-distance-to-the-wall-ahead-trial-1.png``: sorted, and readable in a listing."""
    words = re.sub(r"[^a-z0-9]+", "-", trace.title.lower()).strip("-")[:60]
    return f"plot-{index}-{words or 'trace'}.png"


def save(traces: Sequence[Trace], folder: Path) -> list[Path]:
    """Each trace's plot as a PNG file in ``folder``; raises OSError when it cannot be written."""
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for index, trace in enumerate(traces, start=1):
        path = folder / file_name(index, trace)
        path.write_bytes(png(trace))
        written.append(path)
    return written
