"""Annotated frames: each detection's box with its class, anchor symbol and anchor state.

Every anchor has its own colour (from its symbol), so an identity that persists keeps its
colour from frame to frame and a switch shows as a change of colour. Detections that made no
percept are drawn thin and grey with the reason. Anchors the camera remembers but did not see
in this frame are marked where they project: a ring and their symbol, or only a thin ring for
missing ones (in a busy scene there are many).
"""

from __future__ import annotations

import colorsys
import zlib
from collections.abc import Iterable

import cv2
import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor_demos.replay.pipeline import FrameOutcome

_FONT = cv2.FONT_HERSHEY_SIMPLEX
_GREY = (160, 160, 160)
_WHITE = (255, 255, 255)
_BLACK = (0, 0, 0)
TITLE_HEIGHT = 20  # pixels of the title bar, kept clear of labels


def symbol_colour(symbol: str) -> tuple[int, int, int]:
    """A bright BGR colour that depends on the symbol only."""
    hue = (zlib.crc32(symbol.encode()) % 360) / 360.0
    red, green, blue = colorsys.hsv_to_rgb(hue, 0.85, 1.0)
    return int(255 * blue), int(255 * green), int(255 * red)


def _label(image: np.ndarray, text: str, origin: tuple[int, int], colour: tuple[int, int, int],
           scale: float = 0.45) -> None:
    """Text on a filled box of ``colour``, its bottom-left corner at ``origin`` (kept inside the image)."""
    (width, height), baseline = cv2.getTextSize(text, _FONT, scale, 1)
    x = int(np.clip(origin[0], 0, max(image.shape[1] - width - 2, 0)))
    y = int(np.clip(origin[1], TITLE_HEIGHT + height + baseline + 1, image.shape[0] - 1))
    cv2.rectangle(image, (x, y - height - baseline - 1), (x + width + 2, y), colour, -1)
    luminance = 0.114 * colour[0] + 0.587 * colour[1] + 0.299 * colour[2]
    cv2.putText(image, text, (x + 1, y - baseline), _FONT, scale, _BLACK if luminance > 140 else _WHITE, 1,
                cv2.LINE_AA)


def annotate(outcome: FrameOutcome, anchors: Iterable[Anchor], title: str) -> np.ndarray:
    """The frame as a BGR image with boxes, labels, remembered anchors and a title bar."""
    frame = outcome.frame
    image = cv2.cvtColor(frame.color, cv2.COLOR_RGB2BGR)
    by_symbol = {anchor.symbol: anchor for anchor in anchors}
    seen = {box.symbol for box in outcome.boxes if box.symbol}

    # Remembered anchors first, so the boxes of this frame are drawn over them.
    remembered = [anchor for anchor in by_symbol.values() if anchor.symbol not in seen]
    if remembered:
        points = frame.camera_to_world.inverse().transform_points(np.array([a.position for a in remembered]))
        pixels, depth = frame.intrinsics.project(points)
        for anchor, pixel, z in zip(remembered, pixels, depth, strict=True):
            if not (z > 0 and 0 <= pixel[0] < frame.intrinsics.width and 0 <= pixel[1] < frame.intrinsics.height):
                continue
            centre = (int(round(pixel[0])), int(round(pixel[1])))
            colour = symbol_colour(anchor.symbol)
            if anchor.state is AnchorState.MISSING:  # many, in a busy scene: a thin ring, no label
                cv2.circle(image, centre, 4, colour, 1, cv2.LINE_AA)
                continue
            cv2.circle(image, centre, 6, colour, 2, cv2.LINE_AA)
            _label(image, f"{anchor.symbol} {anchor.state.value}", (centre[0] + 8, centre[1] - 4), colour, 0.38)

    for box in outcome.boxes:
        x_min, y_min, x_max, y_max = (int(round(value)) for value in box.detection.box.corners)
        detection = box.detection
        track = f" #{detection.tracker_id}" if detection.tracker_id else ""
        if not box.symbol:
            cv2.rectangle(image, (x_min, y_min), (x_max, y_max), _GREY, 1)
            _label(image, f"{detection.class_name} {detection.score:.2f}{track}: {box.drop_reason}",
                   (x_min, y_min - 2), _GREY, 0.38)
            continue
        colour = symbol_colour(box.symbol)
        anchor = by_symbol.get(box.symbol)
        state = anchor.state.value if anchor is not None else "?"
        cv2.rectangle(image, (x_min, y_min), (x_max, y_max), colour, 2)
        _label(image, f"{box.symbol} {state}", (x_min, y_min - 2), colour)
        _label(image, f"{detection.class_name} {detection.score:.2f}{track}", (x_min, y_max + 16), colour, 0.38)

    states: dict[str, int] = {}
    for anchor in by_symbol.values():
        states[anchor.state.value] = states.get(anchor.state.value, 0) + 1
    counts = ", ".join(f"{count} {state}" for state, count in sorted(states.items()))
    text = f"{title}  frame {frame.index}  t={frame.stamp:.1f} s  anchors {len(by_symbol)}" + (
        f" ({counts})" if counts else "")
    cv2.rectangle(image, (0, 0), (image.shape[1], TITLE_HEIGHT), _BLACK, -1)
    cv2.putText(image, text, (5, 14), _FONT, 0.45, _WHITE, 1, cv2.LINE_AA)
    return image
