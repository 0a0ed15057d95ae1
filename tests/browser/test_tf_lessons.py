"""The URDF unit completed by clicking only: its buttons type into the dashboard's Console.

(The tf2 unit passes the same way, but takes about 100 s here; the lesson
walk in tests/integration/test_lessons_walk.py covers it on the same code path.)
"""

from __future__ import annotations

import pytest

from tests.browser.helpers import expect_text, open_tab
from tests.browser.test_lessons import complete_by_clicking
from tests.course_data import shared_course

pytestmark = [pytest.mark.browser, pytest.mark.ros]
COURSE = shared_course()


def test_complete_the_urdf_unit_by_clicking(page):
    """robot_state_publisher, state_publisher, the latched description, a slider value."""
    complete_by_clicking(page, COURSE.lesson("18_urdf_robot"))
    open_tab(page, "Console")
    expect_text(page, "$ ros2 topic pub --once /joint_state_sliders")
