"""A top-down map of a run: rooms, furniture, waypoints, where objects really are, and the anchors.

Drawn with OpenCV (already a dependency) rather than matplotlib. A line joins each true object to
the anchor associated with it, so a wrong position is a long line and a missing anchor a lone dot.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np

from merlin2_sailor_demos.report.scorecard import AnchorRecord, TrueObject

Rectangle = tuple[float, float, float, float]
"""x_min, y_min, x_max, y_max in metres."""

_FONT = cv2.FONT_HERSHEY_SIMPLEX
_BLACK, _GREY, _LIGHT = (0, 0, 0), (150, 150, 150), (235, 235, 235)
_TRUE_COLOUR = (60, 160, 60)  # BGR green
_STATE_COLOURS = {"confirmed": (200, 90, 30), "missing": (40, 40, 220), "tentative": (180, 180, 180)}


@dataclass(frozen=True)
class MapLayers:
    """What the map shows besides objects and anchors."""

    rooms: Sequence[tuple[str, Rectangle]] = ()
    furniture: Sequence[Rectangle] = ()
    waypoints: Sequence[tuple[str, float, float]] = ()
    robot_path: Sequence[tuple[float, float]] = field(default_factory=tuple)


def draw_map(
    path: str | Path,
    layers: MapLayers,
    truth: Sequence[TrueObject] = (),
    anchors: Sequence[AnchorRecord] = (),
    association: Mapping[str, str] | None = None,
    title: str = "",
    pixels_per_metre: float = 70.0,
) -> Path:
    """Write the map as a PNG and return its path."""
    points = [(x, y) for _, (x0, y0, x1, y1) in layers.rooms for x, y in ((x0, y0), (x1, y1))]
    points += [(x, y) for _, x, y in layers.waypoints]
    points += [tuple(obj.position[:2]) for obj in truth] + [tuple(a.position[:2]) for a in anchors]
    xy = np.array(points or [(0.0, 0.0)], dtype=float)
    xy = xy[np.all(np.isfinite(xy), axis=1)] if np.isfinite(xy).any() else np.zeros((1, 2))
    low, high = xy.min(axis=0) - 0.8, xy.max(axis=0) + 0.8
    margin_top = 40
    width = int(np.ceil((high[0] - low[0]) * pixels_per_metre))
    height = int(np.ceil((high[1] - low[1]) * pixels_per_metre)) + margin_top + 30
    image = np.full((height, max(width, 420), 3), 255, dtype=np.uint8)

    def pixel(x: float, y: float) -> tuple[int, int]:  # y up on the map, down in the image
        return (
            int(round((x - low[0]) * pixels_per_metre)),
            int(round(margin_top + (high[1] - y) * pixels_per_metre)),
        )

    for name, (x0, y0, x1, y1) in layers.rooms:
        cv2.rectangle(image, pixel(x0, y1), pixel(x1, y0), _LIGHT, -1)
        cv2.rectangle(image, pixel(x0, y1), pixel(x1, y0), _BLACK, 2)
        corner = pixel(x0, y1)
        cv2.putText(image, name, (corner[0] + 4, corner[1] + 16), _FONT, 0.45, _GREY, 1, cv2.LINE_AA)
    for x0, y0, x1, y1 in layers.furniture:
        cv2.rectangle(image, pixel(x0, y1), pixel(x1, y0), (200, 200, 200), -1)
    if len(layers.robot_path) > 1:
        path_pixels = np.array([pixel(x, y) for x, y in layers.robot_path], dtype=np.int32)
        cv2.polylines(image, [path_pixels], False, (210, 170, 120), 1, cv2.LINE_AA)
    for name, x, y in layers.waypoints:
        centre = pixel(x, y)
        cv2.drawMarker(image, centre, _GREY, cv2.MARKER_DIAMOND, 12, 2)
        cv2.putText(image, name, (centre[0] + 8, centre[1] + 16), _FONT, 0.4, _GREY, 1, cv2.LINE_AA)

    by_symbol = {anchor.symbol: anchor for anchor in anchors}
    for obj in truth:
        anchor = by_symbol.get((association or {}).get(obj.id, ""))
        if anchor is not None:
            cv2.line(image, pixel(*obj.position[:2]), pixel(*anchor.position[:2]), _TRUE_COLOUR, 1, cv2.LINE_AA)
    for obj in truth:
        centre = pixel(*obj.position[:2])
        cv2.circle(image, centre, 5, _TRUE_COLOUR, -1, cv2.LINE_AA)
        cv2.putText(image, obj.id, (centre[0] + 6, centre[1] - 4), _FONT, 0.35, _TRUE_COLOUR, 1, cv2.LINE_AA)
    for anchor in anchors:
        if not np.all(np.isfinite(anchor.position[:2])):
            continue
        colour = _STATE_COLOURS.get(anchor.state, _BLACK)
        centre = pixel(*anchor.position[:2])
        cv2.drawMarker(image, centre, colour, cv2.MARKER_CROSS, 12, 2)
        cv2.putText(image, anchor.symbol, (centre[0] + 6, centre[1] + 12), _FONT, 0.38, colour, 1, cv2.LINE_AA)

    cv2.putText(image, title, (10, 26), _FONT, 0.6, _BLACK, 1, cv2.LINE_AA)
    legend = [("true object", _TRUE_COLOUR), ("anchor", _STATE_COLOURS["confirmed"]),
              ("missing anchor", _STATE_COLOURS["missing"])]  # fmt: skip
    x = 10
    for label, colour in legend:
        cv2.circle(image, (x + 5, height - 14), 5, colour, -1)
        cv2.putText(image, label, (x + 14, height - 9), _FONT, 0.4, _BLACK, 1, cv2.LINE_AA)
        x += 30 + 8 * len(label)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(path), image):
        raise OSError(f"could not write the map to {path}")
    return path
