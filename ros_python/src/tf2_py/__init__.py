"""tf2_py: tf2's BufferCore and exceptions for Python, as upstream's binding names them.

Upstream wraps the C++ tf2 library; this is the same API written in Python
(see buffer_core.py, time_cache.py, linear_math.py). ``tf2_ros`` builds on it.
"""

from tf2_py.buffer_core import BufferCore
from tf2_py.exceptions import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)

__all__ = [
    "BufferCore",
    "ConnectivityException",
    "ExtrapolationException",
    "InvalidArgumentException",
    "LookupException",
    "TimeoutException",
    "TransformException",
]
