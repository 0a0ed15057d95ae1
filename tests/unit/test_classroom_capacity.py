"""Learners per core and per GB from bench/classroom_footprint.py's per-learner figures."""

from __future__ import annotations

import math

from bench.classroom_footprint import CORE_SHARE, learners_per_core, learners_per_gb


def test_learners_per_core_keeps_the_headroom():
    assert CORE_SHARE == 0.5
    assert learners_per_core(2.0) == 25.0  # half a core at 2 % a learner
    assert learners_per_core(2.0, share=1.0) == 50.0
    assert math.isnan(learners_per_core(0.0))
    assert math.isnan(learners_per_core(math.nan))


def test_learners_per_gb():
    assert learners_per_gb(128.0) == 8.0
    assert math.isnan(learners_per_gb(0.0))
    assert math.isnan(learners_per_gb(math.nan))
