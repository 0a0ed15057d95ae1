"""rcutils' unnamed logger line, for messages upstream logs without a node."""

from __future__ import annotations

import sys
import time


def rcutils_log(level: str, text: str) -> None:
    """``[WARN] [1700000000.123456789] []: text`` on stderr, as RCUTILS_LOG_* prints it."""
    now = time.time_ns()
    stamp = f"{now // 1_000_000_000}.{now % 1_000_000_000:09d}"
    print(f"[{level}] [{stamp}] []: {text}", file=sys.stderr, flush=True)
