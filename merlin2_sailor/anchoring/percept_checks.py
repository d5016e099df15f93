"""What the anchoring core refuses before it changes anything: percepts it cannot anchor.

A node hands the core whatever arrived on the wire; a percept in the wrong frame, with NaN in its
position or a class no PDDL symbol can be made from would corrupt anchors or fail half-way through
a frame. Everything is checked here first, so a bad frame is refused whole, with a message saying
what was wrong.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import numpy as np

from merlin2_sailor.contract.percept import Percept
from merlin2_sailor.errors import InvalidInputError, KnowledgeError
from merlin2_sailor.knowledge.naming import to_identifier


def check_percepts(percepts: Iterable[Percept], stamp: float, world_frame: str) -> None:
    """Raise InvalidInputError naming the first percept (or the stamp) the core cannot anchor."""
    if not math.isfinite(stamp):
        raise InvalidInputError(f"The frame stamp must be finite, got {stamp}.")
    for number, percept in enumerate(percepts):
        if percept.frame_id != world_frame:
            raise InvalidInputError(
                f"Percept {number} ({percept.class_name}) is in frame {percept.frame_id!r}, but anchors live in "
                f"{world_frame!r}; transform percepts with the camera pose at the image stamp first."
            )
        point(percept.position, f"percept {number} position")
        size = np.asarray(percept.size, dtype=np.float64).reshape(-1)
        if size.shape != (3,) or not np.all(np.isfinite(size)) or np.any(size < 0.0):
            raise InvalidInputError(
                f"Percept {number} size must be 3 finite non-negative numbers, got {size.tolist()}."
            )
        if not math.isfinite(percept.stamp):
            raise InvalidInputError(f"Percept {number} has a non-finite stamp {percept.stamp}.")
        try:  # checked here, before anything changes, not when a symbol is made mid-frame
            to_identifier(percept.class_name)
        except KnowledgeError as error:
            raise InvalidInputError(
                f"Percept {number} has a class name {percept.class_name!r} no symbol can be made from: {error}"
            ) from error


def point(values: Any, name: str) -> np.ndarray:
    """``values`` as a (3,) float64 point; InvalidInputError naming ``name`` otherwise."""
    position = np.asarray(values, dtype=np.float64).reshape(-1)
    if position.shape != (3,) or not np.all(np.isfinite(position)):
        raise InvalidInputError(f"{name} must be 3 finite coordinates, got {np.asarray(values).tolist()}.")
    return position


def position_text(position: np.ndarray) -> str:
    """A position as people read it in a log line: where an object was first seen says much about why."""
    return "(" + ", ".join(f"{float(value):.2f}" for value in position) + ")"


def box_text(position: np.ndarray, size: np.ndarray) -> str:
    """A box as people read it in a log line: "0.35 x 1.60 x 1.00 m at (2.57, 5.80, 0.49)". Why two
    anchors were taken for one object is mostly in their boxes, which the snapshot keeps only for
    the one that stays."""
    return " x ".join(f"{float(value):.2f}" for value in size) + f" m at {position_text(position)}"
