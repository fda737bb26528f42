"""A resource booked in time: a runway or a gate holds one drone at a time.

A :class:`Timetable` keeps the booked intervals of one resource, sorted (by start, then
end, so the ends are sorted too: the searches bisect both) and disjoint;
:meth:`Timetable.free` says whether ``[start, end]`` overlaps none of them (intervals that
only meet at an end point do not overlap; a drone's own bookings do not count against
it), :meth:`Timetable.book` adds one and refuses an overlap with another's,
:meth:`Timetable.forget` drops those that ended before a time (they can no longer matter
to a simulation that has moved past them).

>>> tt = Timetable("runway A")
>>> tt.book(10.0, 20.0, owner=3)
>>> tt.free(0.0, 10.0), tt.free(15.0, 30.0), tt.free(20.0, 25.0)
(True, False, True)
>>> tt.holder(12.0), tt.holder(25.0), tt.free(15.0, 30.0, owner=3)
(3, None, True)
"""

from __future__ import annotations

from bisect import bisect_left, bisect_right


class Timetable:
    """The disjoint booked intervals of one resource (see the module docstring)."""

    def __init__(self, name: str) -> None:
        self.name = name
        self._start: list[float] = []
        self._end: list[float] = []
        self._owner: list[int] = []

    def __len__(self) -> int:
        return len(self._start)

    def _overlapping(self, start: float, end: float) -> range:
        """Indices of the bookings that overlap ``[start, end]`` (touching is not)."""
        k = bisect_left(self._end, start)  # first booking ending at or after start
        while k < len(self._start) and self._end[k] <= start:
            k += 1
        j = k
        while j < len(self._start) and self._start[j] < end:
            j += 1
        return range(k, j)

    def free(self, start: float, end: float, *, owner: int | None = None) -> bool:
        """True when ``[start, end]`` overlaps no booking (touching ends is fine) other
        than ``owner``'s own."""
        return all(self._owner[k] == owner for k in self._overlapping(start, end))

    def book(self, start: float, end: float, *, owner: int) -> None:
        """Hold the resource over ``[start, end]`` for ``owner`` (merged with the owner's
        own bookings it overlaps); an overlap with anyone else's is a bug."""
        if not end >= start:
            raise ValueError(f"{self.name}: booking ends before it starts: {start}, {end}")
        hit = self._overlapping(start, end)
        if not all(self._owner[k] == owner for k in hit):
            raise ValueError(f"{self.name}: [{start}, {end}] overlaps another's booking")
        if len(hit):
            start = min(start, self._start[hit.start])
            end = max(end, self._end[hit.stop - 1])
            del self._start[hit.start:hit.stop], self._end[hit.start:hit.stop]
            del self._owner[hit.start:hit.stop]
        k = bisect_right(self._start, start)
        while k > 0 and self._start[k - 1] == start and self._end[k - 1] > end:
            k -= 1  # equal starts: an instant [t, t] before [t, u], so the ends stay sorted
        self._start.insert(k, start)
        self._end.insert(k, end)
        self._owner.insert(k, owner)

    def holder(self, t: float) -> int | None:
        """The owner holding the resource at ``t`` (a booking ``[a, b]`` holds it on
        ``a <= t < b``), else None."""
        k = bisect_right(self._start, t) - 1
        if k >= 0 and self._start[k] <= t < self._end[k]:
            return self._owner[k]
        return None

    def forget(self, before: float) -> None:
        """Drop the bookings that ended at or before ``before``."""
        k = 0
        while k < len(self._end) and self._end[k] <= before:
            k += 1
        if k:
            del self._start[:k], self._end[:k], self._owner[:k]

    def intervals(self) -> list[tuple[float, float, int]]:
        """The bookings as (start, end, owner), in time order."""
        return list(zip(self._start, self._end, self._owner, strict=True))
