"""tf2's exceptions, as tf2_py exposes them to Python.

One class per failure a learner has to tell apart (the tutorials catch
``TransformException``, the base of all of them). The C++ backward/forward/
no-data extrapolation errors all surface as ``ExtrapolationException`` in
Python, as upstream's binding does.
"""

from __future__ import annotations


class TransformException(Exception):
    """Base of every tf2 error: ``except TransformException`` catches them all."""


class ConnectivityException(TransformException):
    """Both frames exist, but no chain of parents joins them."""


class LookupException(TransformException):
    """A frame is unknown (or the tree is broken, as a loop)."""


class ExtrapolationException(TransformException):
    """The requested time is outside what the cache holds."""


class InvalidArgumentException(TransformException):
    """A frame id is malformed (empty, or starting with '/')."""


class TimeoutException(TransformException):
    """A wait for a transform ran out of time."""


__all__ = [
    "ConnectivityException",
    "ExtrapolationException",
    "InvalidArgumentException",
    "LookupException",
    "TimeoutException",
    "TransformException",
]
