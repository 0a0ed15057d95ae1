"""Where the 3D view's cameras go for a robot that drives about (pure geometry, no browser)."""

from __future__ import annotations

import math

import numpy as np

from app.scene.drive import grown_box, outgrown, padded


def test_a_robot_circling_odom_is_reframed_until_its_whole_way_is_in_view():
    """The URDF lesson's R2-D2 drives a 2 m circle: framed where it first stood, it drove out
    of view. Its frames' box grows with each place it has been; the cameras frame it with a
    metre of room round it, reframe when it drives out of that, and never again once the
    circle is in view."""
    box, framed, reframes = None, None, []
    for tick in range(2 * 360):  # two laps, a degree a tick
        angle = math.radians(tick)
        base = np.array([2.0 * math.cos(angle), 2.0 * math.sin(angle), 0.7])
        links = np.array([base, base + (0.0, 0.0, 0.5), base - (0.0, 0.0, 0.6)])
        box = grown_box(box, links)
        if outgrown(framed, box):
            framed, _ = padded(box, 1.0), reframes.append(tick)
    assert framed is not None and reframes[0] == 0
    assert 3 <= len(reframes) <= 7 and reframes[-1] < 360, reframes  # all in the first lap
    assert (framed[0][:2] <= -2.0).all() and (framed[1][:2] >= 2.0).all()  # the whole circle
    assert (framed[0][:2] >= -3.0).all() and (framed[1][:2] <= 3.0).all()  # and not more
