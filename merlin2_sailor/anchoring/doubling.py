"""When evidence has grown enough to judge an identity again: each time it doubles.

An identity decided on few views (a newcomer's colour, its sightings) is worth judging again as
views come, but not at every view: judging costs matcher calls, and one more view of hundreds
changes nothing. Judging when the count reaches a unit and each time it doubles (1, 2, 4, 8...
times the unit) keeps that to a few times in an anchor's life, each on clearly more evidence.
"""

from __future__ import annotations


def doubled(count: int, unit: int) -> bool:
    """Whether ``count`` is ``unit`` times a power of two (1, 2, 4... times; never for a unit below 1)."""
    if unit < 1 or count < unit or count % unit:
        return False
    times = count // unit
    return times & (times - 1) == 0
