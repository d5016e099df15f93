"""Approximate-time matching of several message streams by their stamps.

An RGB image, its depth image and the camera info arrive on separate topics with stamps that
differ by a few milliseconds (or not at all, for a registered RGB-D driver). ``message_filters``
is not installable here, and its policy is more than this use needs, so this is a small,
deterministic replacement: each input has a bounded queue; whenever a message arrives, the
synchroniser looks for one message per input whose stamps all lie within ``slop`` of each other
and, if there is one, emits it and discards everything at or before it. Late messages, older
than the last emitted set, are dropped because the consumer has moved past them.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from merlin2_sailor.errors import ConfigurationError, InvalidInputError


@dataclass(frozen=True, slots=True)
class SynchroniserConfig:
    """``slop``: the largest stamp spread (seconds) within a matched set; ``queue_size``: how many
    unmatched messages each input keeps before dropping its oldest."""

    slop: float = 0.05
    queue_size: int = 10

    def __post_init__(self) -> None:
        if not (math.isfinite(self.slop) and self.slop >= 0.0):
            raise ConfigurationError(f"slop must be a non-negative number of seconds, got {self.slop}.")
        if self.queue_size < 1:
            raise ConfigurationError(f"queue_size must be at least 1, got {self.queue_size}.")


@dataclass(frozen=True, slots=True)
class MatchedSet:
    """One message per input, by input name, all within the slop; ``stamp`` is the newest stamp."""

    stamp: float
    messages: dict[str, Any]


class ApproximateTimeSynchroniser:
    """Group messages of several named inputs whose stamps are within ``config.slop``."""

    def __init__(self, input_names: Sequence[str], config: SynchroniserConfig | None = None) -> None:
        if len(input_names) < 2 or len(set(input_names)) != len(input_names):
            raise ConfigurationError(
                f"A synchroniser needs at least two distinct input names, got {list(input_names)}."
            )
        self.config = config or SynchroniserConfig()
        self._queues: dict[str, deque[tuple[float, Any]]] = {
            name: deque(maxlen=self.config.queue_size) for name in input_names
        }
        self._last_emitted_stamp = -math.inf

    @property
    def input_names(self) -> tuple[str, ...]:
        return tuple(self._queues)

    def push(self, input_name: str, stamp: float, message: Any) -> MatchedSet | None:
        """Add a message; return the matched set it completes, if any.

        The match is searched around the new message: each other input contributes its message
        nearest in time, and the set is accepted when its spread is at most the slop. Ties go to
        the older message, so the outcome depends on nothing but the stamps.
        """
        if input_name not in self._queues:
            raise InvalidInputError(f"Unknown input {input_name!r}; inputs are {', '.join(self._queues)}.")
        if not math.isfinite(stamp):
            raise InvalidInputError(f"Message stamp must be finite, got {stamp}.")
        if stamp <= self._last_emitted_stamp:
            return None  # late: the consumer already moved past this time
        queue = self._queues[input_name]
        position = len(queue)
        while position > 0 and queue[position - 1][0] > stamp:  # keep each queue sorted by stamp
            position -= 1
        if len(queue) == queue.maxlen:
            if position == 0:
                return None  # older than everything kept in a full queue
            queue.popleft()
            position -= 1
        queue.insert(position, (stamp, message))
        return self._match_around(input_name, stamp)

    def _match_around(self, input_name: str, stamp: float) -> MatchedSet | None:
        chosen: dict[str, tuple[float, Any]] = {}
        for name, queue in self._queues.items():
            if not queue:
                return None
            if name == input_name:
                chosen[name] = next(entry for entry in queue if entry[0] == stamp)
            else:
                chosen[name] = min(queue, key=lambda entry: (abs(entry[0] - stamp), entry[0]))
        stamps = [entry[0] for entry in chosen.values()]
        if max(stamps) - min(stamps) > self.config.slop:
            return None
        for name, (chosen_stamp, _) in chosen.items():
            queue = self._queues[name]
            while queue and queue[0][0] <= chosen_stamp:
                queue.popleft()
        self._last_emitted_stamp = min(stamps)
        return MatchedSet(stamp=max(stamps), messages={name: entry[1] for name, entry in chosen.items()})
