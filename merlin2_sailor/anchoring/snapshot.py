"""Anchors to plain data and back, so they survive a node restart.

The node persists a snapshot through the knowledge layer or a file; either way it must be plain,
JSON-safe data (dicts, lists, strings, numbers). Appearance galleries are the bulk of an anchor,
so they travel as base64 of their little-endian bfloat16 bits (1280-d: 3.4 kB per view) instead
of lists of numbers (~25 kB of JSON each).
"""

from __future__ import annotations

import base64
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.colour_evidence import (
    ColourBySize,
    ColourModel,
    view_key_from_text,
    view_key_text,
)
from merlin2_sailor.anchoring.expectation import Expectation
from merlin2_sailor.anchoring.gallery import GALLERY_DTYPE
from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor.knowledge.model import Provenance
from merlin2_sailor.perception.colour_histogram import COLOUR_BINS

#: Identifies a snapshot; restore refuses anything else.
SNAPSHOT_FORMAT = "merlin2_sailor.anchors"
#: Bump when the layout of :func:`anchor_to_dict` changes incompatibly.
SNAPSHOT_VERSION = 1

_GALLERY_BYTE_ORDER = np.dtype(GALLERY_DTYPE).newbyteorder("<")


def anchor_to_dict(anchor: Anchor) -> dict[str, Any]:
    gallery = None
    if anchor.gallery is not None and len(anchor.gallery):
        gallery = {
            "shape": list(anchor.gallery.shape),
            "bfloat16_base64": base64.b64encode(anchor.gallery.astype(_GALLERY_BYTE_ORDER).tobytes()).decode("ascii"),
        }
        scales = anchor.gallery_scales
        if scales is not None and len(scales) == len(anchor.gallery):
            # JSON has no NaN: an unknown size travels as null.
            gallery["view_scales"] = [None if np.isnan(scale) else float(scale) for scale in scales]
    return {
        "symbol": anchor.symbol,
        "class_name": anchor.class_name,
        "position": anchor.position.tolist(),
        "size": anchor.size.tolist(),
        "first_seen": float(anchor.first_seen),
        "last_seen": float(anchor.last_seen),
        "state": anchor.state.value,
        "times_seen": int(anchor.times_seen),
        "whole_views": int(anchor.whole_views),
        "last_placed": anchor.last_placed,
        "last_tracker_id": anchor.last_tracker_id,
        "class_votes": {name: float(votes) for name, votes in anchor.class_votes.items()},
        "position_variance": float(anchor.position_variance),
        "gallery": gallery,
        "colour": None if anchor.colour is None else _colour_data(anchor.colour),
        "colour_by_size": None if anchor.colour_by_size is None else {
            view_key_text(key): _colour_data(model)
            for key, model in anchor.colour_by_size.ordered()},
        "colour_seen": anchor.colour_seen,
        "colour_disputed": bool(anchor.colour_disputed),
        "doubted_sightings": None if anchor.doubted_sightings is None else list(anchor.doubted_sightings),
        "unverified_sightings": None if anchor.unverified_sightings is None else list(anchor.unverified_sightings),
        "missed_frames": int(anchor.missed_frames),
        "recovery_sightings": int(anchor.recovery_sightings),
        "missing_since": anchor.missing_since,
        "lost_after": anchor.lost_after,
        "lost_at": None if anchor.lost_at is None else anchor.lost_at.tolist(),
        "provenance": anchor.provenance.value,
        "perceived_position": anchor.perceived_position.tolist(),
        "expectation": None if anchor.expectation is None else anchor.expectation.describe(),
        "expectation_confirmed": bool(anchor.expectation_confirmed),
        "indistinguishable_from": list(anchor.indistinguishable_from),
        "found_by_look_alone": anchor.found_by_look_alone,
        "look_pending": list(anchor.look_pending),
        "watched_before": int(anchor.watched_before),
        "seen_with": sorted(anchor.seen_with),
        "parts_fit": None if anchor.parts_fit is None else anchor.parts_fit.tolist(),
    }


def _doubted(value: Any) -> tuple[float, float] | None:
    """A window of doubted (or unverified) sightings, from a snapshot (None where an older one has none)."""
    if value is None:
        return None
    start, end = (float(stamp) for stamp in value)
    return start, end


def anchor_from_dict(data: Mapping[str, Any]) -> Anchor:
    """Rebuild an anchor; it comes back not visible, since nothing has been seen since the restart."""
    try:
        anchor = Anchor(
            symbol=str(data["symbol"]),
            class_name=str(data["class_name"]),
            position=_vector(data["position"], "position"),
            size=_vector(data["size"], "size"),
            first_seen=float(data["first_seen"]),
            last_seen=float(data["last_seen"]),
            state=AnchorState(data["state"]),
            times_seen=int(data["times_seen"]),
            whole_views=int(data.get("whole_views", 0)),
            last_placed=None if data.get("last_placed") is None else float(data["last_placed"]),
            last_tracker_id=str(data.get("last_tracker_id", "")),
            class_votes={str(k): float(v) for k, v in dict(data.get("class_votes") or {}).items()},
            position_variance=float(data["position_variance"]),
            gallery=_gallery(data.get("gallery")),
            gallery_scales=_gallery_scales(data.get("gallery")),
            # A snapshot written before colours were kept by view size: its colour is learnt
            # afresh (a colour no view could be held to would never be checked again).
            colour=_colour(data.get("colour")) if "colour_by_size" in data else None,
            colour_by_size=_colour_by_size(data.get("colour_by_size")),
            colour_seen=None if data.get("colour_seen") is None or "colour_by_size" not in data
            else float(data["colour_seen"]),
            colour_disputed=bool(data.get("colour_disputed", False)) and "colour_by_size" in data,
            doubted_sightings=_doubted(data.get("doubted_sightings")),
            unverified_sightings=_doubted(data.get("unverified_sightings")),
            visible=False,
            missed_frames=int(data.get("missed_frames", 0)),
            recovery_sightings=int(data.get("recovery_sightings", 0)),
            missing_since=None if data.get("missing_since") is None else float(data["missing_since"]),
            lost_after=None if data.get("lost_after") is None else float(data["lost_after"]),
            lost_at=None if data.get("lost_at") is None else _vector(data["lost_at"], "lost_at"),
            provenance=Provenance(data.get("provenance", Provenance.PERCEIVED.value)),
            perceived_position=_vector(data.get("perceived_position", data["position"]), "perceived_position"),
            expectation=None if data.get("expectation") is None else Expectation.from_description(data["expectation"]),
            expectation_confirmed=bool(data.get("expectation_confirmed", False)),
            indistinguishable_from=tuple(str(symbol) for symbol in data.get("indistinguishable_from") or ()),
            found_by_look_alone=str(data.get("found_by_look_alone") or ""),
            look_pending=tuple(str(symbol) for symbol in data.get("look_pending") or ()),
            watched_before=int(data.get("watched_before", 0)),
            seen_with={str(symbol) for symbol in data.get("seen_with") or ()},
            parts_fit=None if data.get("parts_fit") is None else _vector(data["parts_fit"], "parts_fit"),
        )
    except (KeyError, ValueError, TypeError) as error:
        name = data.get("symbol", "?") if isinstance(data, Mapping) else "?"
        raise InvalidInputError(f"Cannot restore anchor {name!r} from its snapshot: {error!r}.") from error
    if not anchor.class_votes:
        anchor.class_votes = {anchor.class_name: 1.0}
    return anchor


def _vector(values: Any, name: str) -> np.ndarray:
    vector = np.asarray(values, dtype=np.float64).reshape(-1)
    if vector.shape != (3,) or not np.all(np.isfinite(vector)):
        raise ValueError(f"{name} must be 3 finite numbers, got {values!r}")
    return vector


def _colour_data(model: ColourModel) -> dict[str, Any]:
    return {"views": int(model.views), "mean": model.mean.tolist(), "squares": model.squares.tolist()}


def _colour_by_size(data: Mapping[str, Any] | None) -> ColourBySize | None:
    """A snapshot's colours by view size and side (None in snapshots written before they were
    kept, or when the anchor had no colour; sizes only, bearing not known, in those written
    before sides)."""
    if data is None:
        return None
    bands = {view_key_from_text(key): _colour(model) for key, model in data.items()}
    if any(model is None for model in bands.values()):
        raise ValueError("colour_by_size must map size bands to colour models")
    return ColourBySize(bands)  # type: ignore[arg-type]


def _colour(data: Mapping[str, Any] | None) -> ColourModel | None:
    """A snapshot's colour model (None in snapshots written before anchors had one)."""
    if data is None:
        return None
    mean = np.asarray(data["mean"], dtype=np.float64)
    squares = np.asarray(data["squares"], dtype=np.float64)
    views = int(data["views"])
    if views < 1 or mean.shape != (COLOUR_BINS,) or squares.shape != (COLOUR_BINS,) \
            or not (np.all(np.isfinite(mean)) and np.all(np.isfinite(squares))):
        raise ValueError(f"colour must hold views >= 1 and {COLOUR_BINS} finite means and squares")
    return ColourModel(views, mean, squares)


def _gallery_scales(data: Mapping[str, Any] | None) -> np.ndarray | None:
    """The sizes of a snapshot's gallery views (None in snapshots written before they were kept)."""
    if data is None or data.get("view_scales") is None:
        return None
    scales = np.array([np.nan if scale is None else float(scale) for scale in data["view_scales"]], dtype=np.float32)
    if len(scales) != int(data["shape"][0]) or np.any(scales[~np.isnan(scales)] < 0.0):
        raise ValueError(f"view_scales must hold one size >= 0 (or null) per gallery view, got {data['view_scales']!r}")
    return scales


def _gallery(data: Mapping[str, Any] | None) -> np.ndarray | None:
    if data is None:
        return None
    shape = tuple(int(n) for n in data["shape"])
    raw = base64.b64decode(data["bfloat16_base64"], validate=True)
    gallery = np.frombuffer(raw, dtype=_GALLERY_BYTE_ORDER)
    if len(shape) != 2 or gallery.size != shape[0] * shape[1]:
        raise ValueError(f"gallery bytes do not fill the shape {shape}")
    return gallery.reshape(shape).astype(GALLERY_DTYPE)


def snapshot_of(anchors: Iterable[Anchor], world_frame: str, stamp: float | None) -> dict[str, Any]:
    """Every anchor as plain, JSON-safe data, in symbol order, with the frame they live in."""
    return {
        "format": SNAPSHOT_FORMAT,
        "version": SNAPSHOT_VERSION,
        "world_frame": world_frame,
        "stamp": stamp,
        "anchors": [anchor_to_dict(anchor) for anchor in sorted(anchors, key=lambda a: a.symbol)],
    }


def anchors_of_snapshot(snapshot: Mapping[str, Any], world_frame: str) -> tuple[list[Anchor], float | None]:
    """The anchors of a snapshot (forgotten ones included) and its stamp; refuses a snapshot of
    another format, version or frame, and one naming a symbol twice."""
    if not isinstance(snapshot, Mapping) or snapshot.get("format") != SNAPSHOT_FORMAT:
        raise InvalidInputError(f"Not an anchors snapshot (expected format {SNAPSHOT_FORMAT!r}).")
    if snapshot.get("version") != SNAPSHOT_VERSION:
        raise InvalidInputError(
            f"Anchors snapshot version {snapshot.get('version')!r} is not supported "
            f"(this code reads version {SNAPSHOT_VERSION})."
        )
    if snapshot.get("world_frame", world_frame) != world_frame:
        raise InvalidInputError(
            f"The snapshot's anchors are in frame {snapshot['world_frame']!r}, this core anchors in "
            f"{world_frame!r}; positions would be meaningless."
        )
    anchors = [anchor_from_dict(data) for data in snapshot.get("anchors", ())]
    symbols = [anchor.symbol for anchor in anchors]
    if len(set(symbols)) != len(symbols):
        raise InvalidInputError("The anchors snapshot names a symbol twice.")
    stamp = snapshot.get("stamp")
    return anchors, None if stamp is None else float(stamp)
