"""Per-frame history of transforms to the parent: tf2's TimeCache and StaticCache.

A dynamic frame keeps ``cache_time`` of stamped transforms (10 s by default),
sorted by stamp so a lookup is a bisection, and answers between two stamps by
interpolating (translation linearly, rotation by slerp). A static frame keeps
one transform that holds at every time. Times are integer nanoseconds; 0 means
"the latest". Errors come back as values (``CacheError``), not exceptions:
the buffer decides what a failed step means for the whole chain.
"""

from __future__ import annotations

from bisect import bisect_left, bisect_right
from dataclasses import dataclass

from tf2_py.linear_math import Quat, Vec, slerp

# Error codes, as tf2::TF2Error numbers them (the first seven are tf2_msgs/TF2Error's).
NO_ERROR = 0
LOOKUP_ERROR = 1
CONNECTIVITY_ERROR = 2
EXTRAPOLATION_ERROR = 3
INVALID_ARGUMENT_ERROR = 4
TIMEOUT_ERROR = 5
TRANSFORM_ERROR = 6
BACKWARD_EXTRAPOLATION_ERROR = 7
FORWARD_EXTRAPOLATION_ERROR = 8
NO_DATA_FOR_EXTRAPOLATION_ERROR = 9

Entry = tuple[int, Quat, Vec]  # (parent frame number, rotation, translation)


@dataclass(frozen=True)
class CacheError:
    code: int
    message: str


def display_time(stamp_ns: int) -> str:
    """tf2's ``displayTimePoint``: seconds with six decimals."""
    return f"{stamp_ns / 1e9:.6f}"


class TimeCache:
    """Stamped transforms of one frame over the last ``max_storage_ns``."""

    __slots__ = ("_max", "_stamps", "_data", "_lo")

    def __init__(self, max_storage_ns: int = 10_000_000_000) -> None:
        self._max = max_storage_ns
        self._stamps: list[int] = []  # ascending; entries before _lo are pruned
        self._data: list[Entry] = []
        self._lo = 0

    # -- reading -------------------------------------------------------------
    def get_data(self, time_ns: int) -> Entry | CacheError:
        """The transform at ``time_ns`` (0: the newest), interpolated between stamps."""
        stamps, lo = self._stamps, self._lo
        n = len(stamps)
        if n == lo:
            return CacheError(NO_DATA_FOR_EXTRAPOLATION_ERROR, "")
        if time_ns == 0:
            return self._data[-1]
        if n - lo == 1:
            if stamps[lo] == time_ns:
                return self._data[lo]
            return CacheError(
                NO_DATA_FOR_EXTRAPOLATION_ERROR,
                f"Lookup would require extrapolation at time {display_time(time_ns)}, "
                f"but only time {display_time(stamps[lo])} is in the buffer",
            )
        latest, earliest = stamps[-1], stamps[lo]
        if time_ns == latest:
            return self._data[-1]
        if time_ns == earliest:
            return self._data[lo]
        if time_ns > latest:
            return CacheError(
                FORWARD_EXTRAPOLATION_ERROR,
                "Lookup would require extrapolation into the future.  Requested time "
                f"{display_time(time_ns)} but the latest data is at time {display_time(latest)}",
            )
        if time_ns < earliest:
            return CacheError(
                BACKWARD_EXTRAPOLATION_ERROR,
                "Lookup would require extrapolation into the past.  Requested time "
                f"{display_time(time_ns)} but the earliest data is at time "
                f"{display_time(earliest)}",
            )
        i = bisect_right(stamps, time_ns, lo) - 1  # newest entry at or before time_ns
        older = self._data[i]
        t0 = stamps[i]
        if t0 == time_ns:
            return older
        newer = self._data[i + 1]
        if older[0] != newer[0]:  # the parent changed between the two: no blending
            return older
        r = (time_ns - t0) / (stamps[i + 1] - t0)
        (ax, ay, az), (bx, by, bz) = older[2], newer[2]
        return (
            older[0],
            slerp(older[1], newer[1], r),
            (ax + (bx - ax) * r, ay + (by - ay) * r, az + (bz - az) * r),
        )

    def get_parent(self, time_ns: int) -> int | CacheError:
        parent = self.parent_at(time_ns)
        if parent:
            return parent
        found = self.get_data(time_ns)  # no parent then: the error, with its message
        return found if isinstance(found, CacheError) else found[0]

    def parent_at(self, time_ns: int) -> int:
        """The parent at ``time_ns`` (tf2's getParent: the older neighbour's), 0 if none.

        Only a bisection: no interpolation and no error message, for walks
        that need the tree's shape before any maths.
        """
        stamps, lo = self._stamps, self._lo
        n = len(stamps)
        if n == lo:
            return 0
        if time_ns == 0:
            return self._data[-1][0]
        if time_ns < stamps[lo] or time_ns > stamps[-1]:
            return 0
        return self._data[bisect_right(stamps, time_ns, lo) - 1][0]

    def latest_time_and_parent(self) -> tuple[int, int]:
        if len(self._stamps) == self._lo:
            return 0, 0
        return self._stamps[-1], self._data[-1][0]

    def latest_stamp(self) -> int:
        return self._stamps[-1] if len(self._stamps) > self._lo else 0

    def oldest_stamp(self) -> int:
        return self._stamps[self._lo] if len(self._stamps) > self._lo else 0

    def __len__(self) -> int:
        return len(self._stamps) - self._lo

    # -- writing -------------------------------------------------------------
    def insert(self, stamp_ns: int, entry: Entry) -> bool:
        """Store one transform; False if it is older than the cache keeps (TF_OLD_DATA)."""
        stamps = self._stamps
        had_data = len(stamps) > self._lo
        latest = stamps[-1] if had_data else 0
        self._prune(latest)
        if had_data and stamp_ns < latest - self._max:
            return False
        if not had_data or stamp_ns > latest:
            stamps.append(stamp_ns)
            self._data.append(entry)
        else:
            first = bisect_left(stamps, stamp_ns, self._lo)
            end = bisect_right(stamps, stamp_ns, first)
            if any(self._data[k] == entry for k in range(first, end)):
                return True  # the same data again: nothing to add
            stamps.insert(end, stamp_ns)
            self._data.insert(end, entry)
        return True

    def _prune(self, latest: int) -> None:
        stamps = self._stamps
        cut = bisect_left(stamps, latest - self._max, self._lo)
        if cut > self._lo:
            self._lo = cut
            if cut > 64 and cut * 2 > len(stamps):  # compact now and then, not per insert
                del stamps[:cut]
                del self._data[:cut]
                self._lo = 0

    def clear(self) -> None:
        self._stamps.clear()
        self._data.clear()
        self._lo = 0


class StaticCache:
    """One transform of a static frame: valid at every time."""

    __slots__ = ("_entry",)

    def __init__(self) -> None:
        self._entry: Entry | None = None

    def get_data(self, time_ns: int) -> Entry | CacheError:
        if self._entry is None:
            return CacheError(NO_DATA_FOR_EXTRAPOLATION_ERROR, "")
        return self._entry

    def get_parent(self, time_ns: int) -> int | CacheError:
        return self._entry[0] if self._entry is not None else 0

    def parent_at(self, time_ns: int) -> int:
        return self._entry[0] if self._entry is not None else 0

    def latest_time_and_parent(self) -> tuple[int, int]:
        return 0, (self._entry[0] if self._entry is not None else 0)

    def latest_stamp(self) -> int:
        return 0

    def oldest_stamp(self) -> int:
        return 0

    def __len__(self) -> int:
        return 1

    def insert(self, stamp_ns: int, entry: Entry) -> bool:
        self._entry = entry
        return True

    def clear(self) -> None:
        """Static data survives a clear, as in tf2."""
