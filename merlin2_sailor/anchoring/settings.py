"""The anchoring layer's settings: every parameter in one table, its default read from the dataclasses.

The anchoring node, ``sailor replay``, ``sailor evaluate`` and the benchmarks must run the same
system, so they build it from the same values the same way:

* the defaults are the frozen config dataclasses' own (``AnchoringConfig`` and its parts, the
  matcher's, the persistence's): a :class:`Setting` names the path of its field in an
  :class:`AnchoringSettings` and reads its default there, so no second copy of a default exists;
* :data:`SETTINGS` is the table of every parameter: its name in YAML and ROS, where it goes, what
  it means and its range. The node declares its ROS parameters from it (with descriptors), and
  config/anchoring.yaml documents every row (``python -m merlin2_sailor.anchoring.settings``
  prints that file from the table);
* :func:`settings_from_parameters` applies a mapping of parameter values to the defaults
  generically (one ``dataclasses.replace`` per changed dataclass, whatever the field), checking
  each value's type and range as rclpy does for the node; :func:`load_anchoring_settings` reads
  the values from the same ROS parameter files ``sailor launch`` hands the node.

A new setting is one field in its dataclass and one row here (a test fails while a field has no
row, or config/anchoring.yaml does not document it).
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import os
import textwrap
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from types import MappingProxyType
from typing import Any

import yaml

from merlin2_sailor.anchoring.anchoring import AnchoringConfig
from merlin2_sailor.anchoring.matcher_registry import MATCHER_ENTRIES, MatcherSettings
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.inference.settings import DEVICES, PRECISIONS, RUNTIMES

#: The anchoring node's default name; the node sections of a parameter file are matched against it.
NODE_NAME = "anchoring"
#: What an offline tool (replay, evaluation, benchmark) changes of a deployment's settings: it
#: syncs no knowledge base and keeps no state on disk.
OFFLINE_OVERRIDES: Mapping[str, Any] = MappingProxyType({"knowledge_base": "", "state_folder": ""})


@dataclass(frozen=True, slots=True)
class PersistenceSettings:
    """Where the anchors go besides memory: ``knowledge_base`` (a store location, "" for none),
    ``grounding`` (its YAML, "" for config/grounding.yaml), ``state_folder`` (anchors and symbol
    counters, "" to keep nothing), the worker's ``sync_period`` / ``save_period`` (s), and
    ``knowledge_base_timeout`` (s): how long one knowledge-base call may wait before the sync is
    retried (short: the worker saves nothing while it waits)."""

    knowledge_base: str = "ros:///merlin2"
    grounding: str = ""
    state_folder: str = "~/.sailor/anchoring"
    sync_period: float = 0.5
    save_period: float = 2.0
    knowledge_base_timeout: float = 2.0

    def __post_init__(self) -> None:
        for name in ("sync_period", "save_period", "knowledge_base_timeout"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ConfigurationError(f"persistence {name} must be a positive number of seconds, got {value}.")


#: The most percept arrays the node keeps waiting: more would anchor frames ever further behind the
#: camera, each judged against a camera pose and depth image that must still be buffered.
MAXIMUM_FRAME_BACKLOG = 30


@dataclass(frozen=True, slots=True)
class TimingSettings:
    """The node's clockwork: ``track_period`` (s between Track steps), ``stamp_tolerance`` (the
    largest gap, s, between percepts and the camera pose / depth image they are judged with) and
    ``frame_backlog`` (percept arrays kept waiting while a frame is anchored, the oldest let go
    beyond: a burst of new objects to embed is caught up on rather than its sightings lost)."""

    track_period: float = 0.5
    stamp_tolerance: float = 0.05
    frame_backlog: int = 4

    def __post_init__(self) -> None:
        if not (math.isfinite(self.track_period) and self.track_period > 0.0):
            raise ConfigurationError(
                f"timing track_period must be a positive number of seconds, got {self.track_period}.")
        if not (math.isfinite(self.stamp_tolerance) and self.stamp_tolerance >= 0.0):
            raise ConfigurationError(f"timing stamp_tolerance must be >= 0 seconds, got {self.stamp_tolerance}.")
        if not 1 <= self.frame_backlog <= MAXIMUM_FRAME_BACKLOG:
            raise ConfigurationError(
                f"timing frame_backlog must be 1 to {MAXIMUM_FRAME_BACKLOG} frames, got {self.frame_backlog}.")


POSE_SOURCES = ("topic", "tf")


@dataclass(frozen=True, slots=True)
class InputSettings:
    """Where the node takes the camera pose from: ``pose_source`` ``topic`` (PoseStamped on
    camera_pose) or ``tf`` (TF, the camera info's optical frame in the world frame at each stamp)."""

    pose_source: str = "topic"

    def __post_init__(self) -> None:
        if self.pose_source not in POSE_SOURCES:
            raise ConfigurationError(f"inputs pose_source must be one of {', '.join(POSE_SOURCES)}, "
                                     f"got '{self.pose_source}'.")


@dataclass(frozen=True, slots=True)
class AnchoringSettings:
    """Everything the anchoring service is built from: the ``core`` (:class:`AnchoringConfig`), the
    ``matcher``, the ``persistence``, the node's ``timing`` and its camera ``inputs``."""

    core: AnchoringConfig = field(default_factory=AnchoringConfig)
    matcher: MatcherSettings = field(default_factory=MatcherSettings)
    persistence: PersistenceSettings = field(default_factory=PersistenceSettings)
    timing: TimingSettings = field(default_factory=TimingSettings)
    inputs: InputSettings = field(default_factory=InputSettings)


@cache
def default_settings() -> AnchoringSettings:
    """The defaults, once: frozen, so sharing one instance is safe."""
    return AnchoringSettings()


def value_at(settings: Any, path: tuple[str, ...]) -> Any:
    """The field ``path`` leads to, attribute by attribute, from ``settings``."""
    value = settings
    for name in path:
        value = getattr(value, name)
    return value


@dataclass(frozen=True, slots=True)
class Setting:
    """One parameter: ``name`` (in YAML and ROS), ``path`` (its field in :class:`AnchoringSettings`),
    ``description`` (what it does and why one would change it), an optional numeric range
    (``minimum`` / ``maximum``, inclusive, as ROS descriptors have them) or ``choices``, and
    ``deployment``: a choice of each deployment (a path, the knowledge base) that
    config/anchoring.yaml may set to something else than the default. ``group`` heads it in
    config/anchoring.yaml."""

    name: str
    path: tuple[str, ...]
    description: str
    minimum: float | None = None
    maximum: float | None = None
    choices: tuple[str, ...] = ()
    deployment: bool = False
    group: str = ""

    @property
    def default(self) -> Any:
        """The default, read from a default-constructed :class:`AnchoringSettings`."""
        return value_at(default_settings(), self.path)

    @property
    def range_text(self) -> str:
        """The range as config/anchoring.yaml and error messages say it ("0.01 to 10"), or ""."""
        if self.choices:
            return "one of " + ", ".join(self.choices)
        if self.minimum is None and self.maximum is None:
            return ""
        return f"{_number(self.minimum)} to {_number(self.maximum)}"

    def check(self, value: Any, source: str) -> None:
        """Refuse a value of the wrong type, out of range or not among the choices, as rclpy does
        for the node's parameters (an integer for a float parameter included: write 600.0)."""
        default = self.default
        expected = type(default)
        if type(value) is not expected:
            hint = f" (write {value!r}.0)" if expected is float and type(value) is int else ""
            raise ConfigurationError(
                f"anchoring parameter '{self.name}' from {source} must be {_TYPE_NAMES[expected]}, "
                f"got {value!r}{hint}")
        if self.choices and value not in self.choices:
            raise ConfigurationError(
                f"anchoring parameter '{self.name}' from {source} must be one of {', '.join(self.choices)}, "
                f"got {value!r}")
        low = -math.inf if self.minimum is None else self.minimum
        high = math.inf if self.maximum is None else self.maximum
        if isinstance(value, (int, float)) and not isinstance(value, bool) and not (low <= value <= high):
            raise ConfigurationError(
                f"anchoring parameter '{self.name}' from {source} must be {self.range_text}, got {value!r}")


_TYPE_NAMES = {bool: "true or false", int: "an integer", float: "a float", str: "a string"}


def _number(value: float | None) -> str:
    if value is None:
        return "any"
    return str(int(value)) if float(value).is_integer() else f"{value:g}"


def _group(title: str, *rows: Setting) -> tuple[Setting, ...]:
    return tuple(dataclasses.replace(row, group=title) for row in rows)


SETTINGS: tuple[Setting, ...] = (
    *_group(
        "Frame and matching function",
        Setting("world_frame", ("core", "world_frame"),
                "Fixed frame the anchors live in (the percepts must be in it)."),
        Setting("matcher", ("matcher", "name"),
                "Matching function: network (the learned matching function of the paper, comparing crops "
                "too: embeds each new crop, ~4 ms on two CPU cores with OpenVINO) or rules (class, distance, "
                "time; hand-tuned, no appearance: the baseline).", choices=tuple(sorted(MATCHER_ENTRIES))),
        Setting("weights", ("matcher", "weights"),
                "Weights file of the matching network (\"\" uses the weights shipped in "
                "merlin2_sailor/models, trained by scripts/make_default_weights.sh).", deployment=True),
        Setting("backbone", ("matcher", "backbone"),
                "Crop backbone the network's weights were trained with; the crop embedder runs it."),
        Setting("match_threshold", ("core", "match_threshold"),
                "Score a percept-anchor pair needs to reacquire the anchor (the paper's 0.5); a percept "
                "with no such pair acquires a new anchor.", 0.01, 1.0),
    ),
    *_group(
        "Inference (the network and the crop backbone; unused by the rules)",
        Setting("inference_runtime", ("matcher", "inference", "runtime"),
                "openvino (models exported once from torch, then run without it: several times faster on a "
                "CPU) or native (torch itself, the baseline).", choices=RUNTIMES),
        Setting("inference_device", ("matcher", "inference", "device"),
                "OpenVINO device: CPU, GPU or AUTO; a device this machine lacks falls back to the CPU with one "
                "log line.", choices=DEVICES),
        Setting("inference_threads", ("matcher", "inference", "threads"),
                "Threads for inference, 0 for every core (a robot shares its cores: give this node what it "
                "may take).", 0, 256),
        Setting("inference_precision", ("matcher", "inference", "precision"),
                "OpenVINO precision: f32 (as torch: the scores the weights were validated with) or auto (the "
                "device's fastest: bfloat16 where the CPU has it, about twice as fast; match scores then move "
                "by up to 0.05).", choices=PRECISIONS),
        Setting("crop_reuse_tolerance", ("matcher", "crop_reuse_tolerance"),
                "Grey levels (mean difference of 16 x 16 thumbnails) under which a crop takes the embedding "
                "of a crop of the same size embedded in the last 3 frames: a still camera's untracked "
                "detections are not embedded anew every frame; 0 embeds every crop.", 0.0, 50.0),
    ),
    *_group(
        "Rule matcher (also the network's fallback for pairs without an embedding)",
        Setting("rules_position_sigma", ("matcher", "rules", "position_sigma"),
                "Distance tolerance (m) of a percept and an anchor seen at the same time.", 0.01, 10.0),
        Setting("rules_drift_speed", ("matcher", "rules", "drift_speed"),
                "How fast (m/s) the tolerance grows while the anchor is unseen (an object may have been "
                "nudged).", 0.0, 10.0),
        Setting("rules_maximum_sigma", ("matcher", "rules", "maximum_sigma"),
                "The tolerance's cap (m) however long the anchor has been unseen; at least "
                "rules_position_sigma.", 0.01, 10.0),
        Setting("rules_time_scale", ("matcher", "rules", "features", "time_scale"),
                "Seconds over which the rules' time feature decays (0.5 at about 1.1 time scales); the "
                "network reads its own from its weights.", 0.1, 1e6),
    ),
    *_group(
        "Matching table: which pairs are scored at all (gating) and tracker evidence",
        Setting("gate_base", ("core", "table", "base_gate"),
                "Reach (m) of an anchor seen just now: farther percepts are not scored against it.",
                0.01, 100.0),
        Setting("gate_maximum_speed", ("core", "table", "maximum_speed"),
                "How fast (m/s) an unseen object may plausibly have been moved: the reach grows by it.",
                0.0, 100.0),
        Setting("gate_maximum", ("core", "table", "maximum_gate"),
                "The reach's cap (m), at least gate_base, so that long-unseen anchors do not become "
                "candidates for every percept in the house.", 0.01, 1000.0),
        Setting("gate_class_mismatch", ("core", "table", "gate_class_mismatch"),
                "Never pair a percept with an anchor of another class."),
        Setting("tracker_continuity_score", ("core", "table", "tracker_continuity_score"),
                "The score floor of a pair continuing the anchor's tracker id.", 0.01, 1.0),
        Setting("continuation_maximum_age", ("core", "table", "continuation_maximum_age"),
                "How recently (s) a tracker id's anchor must have been seen for the percept to be taken "
                "as it without scoring (about a tracker's buffer).", 0.0, 60.0),
        Setting("continuation_maximum_distance", ("core", "table", "continuation_maximum_distance"),
                "How far (m) from its anchor a percept's tracker id still counts (a 2D tracker swaps ids "
                "between nearby objects when the camera turns).", 0.01, 10.0),
        Setting("continuation_nearest_margin", ("core", "table", "continuation_nearest_margin"),
                "A tracker id does not count either when another anchor of the class is nearer the percept "
                "by more than this (m).", 0.0, 10.0),
        Setting("gated_score", ("core", "table", "gated_score"),
                "The penalty score gated pairs hold before assignment (negative: below any real score).",
                -100.0, -0.001),
        Setting("search_score_cap", ("core", "table", "search_score_cap"),
                "The most a pair with an anchor being searched for can score: below an in-place match, so "
                "a look-alike anchored where the search looks keeps its own percept.", 0.01, 1.0),
    ),
    *_group(
        "Fusion: how a reacquired percept updates its anchor",
        Setting("fusion_measurement_variance", ("core", "fusion", "measurement_variance"),
                "A percept position's noise (m^2; 0.01 is a 10 cm standard deviation).", 1e-6, 100.0),
        Setting("fusion_drift_variance_rate", ("core", "fusion", "drift_variance_rate"),
                "How fast (m^2/s) the uncertainty about an unseen anchor's position grows.", 0.0, 100.0),
        Setting("fusion_initial_variance", ("core", "fusion", "initial_variance"),
                "The variance (m^2) of a newly acquired anchor's position.", 1e-6, 100.0),
        Setting("fusion_size_smoothing", ("core", "fusion", "size_smoothing"),
                "The weight of a new size measurement once the anchor is well known.", 0.01, 1.0),
        Setting("gallery_size", ("core", "fusion", "gallery_size"),
                "How many views' appearance embeddings an anchor keeps (a new view replaces the one "
                "nearest in size).", 1, 1000),
        Setting("partial_view_variance_factor", ("core", "fusion", "partial_view_variance_factor"),
                "How many times less a partial view (cut by the image's edge or an occluder) moves an "
                "anchor than a whole one.", 1.0, 1e6),
    ),
    *_group(
        "Partial views: a view cut by the image's edge or a nearer surface",
        Setting("partial_view_edge_margin", ("core", "partial_view", "edge_margin"),
                "A box within this many pixels of the image's edge is cut by it.", 0.0, 1000.0),
        Setting("partial_view_occluder_margin", ("core", "partial_view", "occluder_margin"),
                "How much nearer (m) than the object a surface beside its box must be to cut it.",
                0.001, 10.0),
        Setting("partial_view_strip_width", ("core", "partial_view", "strip_width"),
                "Width (pixels) of the strips beside a box where occluders are looked for.", 1, 100),
    ),
    *_group(
        "Lifecycle: tentative -> confirmed -> missing -> forgotten",
        Setting("confirm_after", ("core", "lifecycle", "confirm_after"),
                "Sightings a new anchor (or a missing one coming back) needs to be confirmed, so one false "
                "detection never reports an object.", 1, 1000),
        Setting("missed_frames_to_missing", ("core", "lifecycle", "missed_frames_to_missing"),
                "Consecutive frames an anchor must be expected in view yet unseen to be marked missing "
                "(more than one rides out a detector's flicker).", 1, 1000),
        Setting("forget_after", ("core", "lifecycle", "forget_after"),
                "Seconds a confirmed anchor may stay missing before it is forgotten and leaves the knowledge "
                "base (a missing object is still knowledge: \"cup_2 exists, place unknown\", which a search "
                "can act on).", 0.0, 1e9),
        Setting("forget_tentative_after", ("core", "lifecycle", "forget_tentative_after"),
                "Seconds a never-confirmed anchor (often a false detection) survives not being seen where "
                "it should have been.", 0.0, 3600.0),
        Setting("confirm_within", ("core", "lifecycle", "confirm_within"),
                "Seconds within which a never-confirmed anchor's sightings, or a missing one's, must follow "
                "one another to add up to a confirmation (sparse sightings at one spot are a detector's "
                "false positives).",
                0.0, 3600.0),
    ),
    *_group(
        "Visibility: when not seeing an anchor counts towards missing",
        Setting("visible_near", ("core", "visibility", "frustum", "near"),
                "Nearest an anchor may be from the camera (m) and still be expected in view.", 0.0, 100.0),
        Setting("visible_range", ("core", "visibility", "frustum", "far"),
                "Farthest an anchor may be from the camera (m) and still be expected in view. Keep it "
                "within the percept generator's maximum_depth: an object beyond that is never perceived, "
                "and would be marked missing.", 0.3, 1000.0),
        Setting("visible_margin", ("core", "visibility", "frustum", "margin"),
                "Pixels of the image's border where an anchor is not expected to be seen (an object "
                "centred there is usually cut off and missed).", 0.0, 1000.0),
        Setting("occlusion_margin", ("core", "visibility", "occlusion_margin"),
                "How much nearer (m) than an anchor's front a depth reading must be to hide it.", 0.0, 10.0),
        Setting("visible_in_image_share", ("core", "visibility", "in_image_share"),
                "Share of an anchor's projected 3D box that must be inside the image for it to be expected "
                "in view (a large object close by, its centre in the image but mostly outside it, is not "
                "detected; 0 turns it off).", 0.0, 1.0),
    ),
    *_group(
        "Identity: expectations, searches and reappearances",
        Setting("expectation_tolerance", ("core", "expectation_tolerance"),
                "How close (m) to an expected place a reacquired object must be to confirm the expectation "
                "(farther retracts it); a search's radius is widened by it too.", 0.01, 100.0),
        Setting("reappearance_distance", ("core", "repair", "reappearance_distance"),
                "How close (m) to a missing anchor a newcomer of its class must be confirmed to be considered "
                "as it reappearing (below the 0.3 m between books on a shelf; 0 turns it off).", 0.0, 10.0),
        Setting("ambiguity_margin", ("core", "repair", "ambiguity_margin"),
                "How much better than every rival a candidate for a merge must score to be taken (scores "
                "closer than this cannot tell two look-alikes apart: nothing is merged, and it is said).",
                0.0, 0.99),
        Setting("same_space_overlap", ("core", "repair", "same_space_overlap"),
                "Share of the smaller 3D box that a missing anchor and an anchor of its class seen in its "
                "place must have in common to be one object (two objects cannot fill one space): the younger "
                "is a second anchor left by a slip, and goes (0 turns it off).", 0.0, 1.0),
        Setting("part_slack", ("core", "repair", "part_slack"),
                "Share by which the box around two anchors of a large object's class, never seen at one "
                "time, one of them a part, may exceed the largest one of the class seen whole for them to "
                "be parts of one object, seen in pieces: the younger goes into the older (0 turns it off).",
                0.0, 1.0),
        Setting("stand_in_distance", ("core", "repair", "stand_in_distance"),
                "How close (m) to an anchor that was away a newcomer of its class, seen only while it was "
                "away and gone as it came back, must stand to be that anchor seen off its place (a pose "
                "error for a moment); it is forgotten and the older symbol stays (0 turns it off).", 0.0, 10.0),
        Setting("place_jump", ("core", "repair", "place_jump"),
                "How far (m) from a place an anchor must have gone, by a sudden move (half of it in one "
                "sighting), for a newcomer of its class seen soon after on that place to show that the move "
                "went to a look-alike: the anchor goes back to its object and the newcomer takes the "
                "look-alike (0 turns it off).", 0.0, 10.0),
        Setting("place_review", ("core", "repair", "place_review"),
                "For how long (s) after such a jump a newcomer on the place left is looked for.", 0.0, 60.0),
        Setting("carry_speed", ("core", "repair", "carry_speed"),
                "How fast (m/s) someone may have carried an object away, walking with it: an anchor first "
                "seen farther from where a missing one was last perceived before it went missing than this "
                "speed covers in the time between (plus the reappearance distance and half of each object's "
                "size) is another object, never merged into it (0 turns that off).", 0.0, 100.0),
        Setting("relocation_watched_frames", ("core", "watch", "frames_to_arrive"),
                "Frames the camera must have watched a place, with no unknown object of a class in it, for an "
                "object of that class first seen there to count as having arrived (moved): only such an object "
                "is merged into a missing anchor of its colour without a search (0 turns that off).", 0, 100000),
        Setting("watch_cell", ("core", "watch", "cell"),
                "Side (m) of the floor-plan cells in which the camera's watching is counted.", 0.01, 10.0),
        Setting("watch_radius", ("core", "watch", "radius"),
                "How far (m) around each percept the camera counts as watching (the detector worked there).",
                0.0, 10.0),
        Setting("colour_minimum_views", ("core", "colour", "minimum_views"),
                "Whole views an anchor needs before its colour (of the object's own pixels) is known; one of "
                "two anchors compared must know it before colours may rule out that they are one object "
                "(0 turns colour evidence off).", 0, 1000),
        Setting("colour_minimum_difference", ("core", "colour", "minimum_difference"),
                "Share of an object's pixels by which one 60-degree hue window (or a grey level) of two "
                "anchors must differ to rule out a merge (a red mug's red is about 0.12-0.2).", 0.001, 0.999),
        Setting("colour_noise_factor", ("core", "colour", "noise_factor"),
                "How many standard deviations of the two anchors' own views that difference must also "
                "exceed (views of one object vary with light and angle).", 0.0, 100.0),
        Setting("colour_absence", ("core", "colour", "absence"),
                "Seconds an anchor's colour must have gone unchecked (no whole view with a colour) before "
                "one whole view of another colour rules out that it is the anchor's object (a look-alike "
                "put in its place while the camera looked away); 0: always.", 0.0, 1e6),
        Setting("colour_comparable_size", ("core", "colour", "comparable_size"),
                "One whole view is held only to the anchor's whole views at most this many times larger "
                "or smaller (square root of the box's area): a view's colour changes with the size it is seen "
                "at; with fewer than colour_minimum_views such views nothing is ruled out.", 1.0, 100.0),
        Setting("colour_comparable_bearing", ("core", "colour", "comparable_bearing"),
                "One whole view is held only to the anchor's whole views seen from at most this many degrees "
                "around the object from it (object to camera, horizontally): an object's colour is not the same "
                "from every side; 180: every side.", 1.0, 180.0),
        Setting("colour_minimum_difference_across_sides", ("core", "colour", "minimum_difference_across_sides"),
                "Share of an object's pixels by which two anchors' colours must differ to rule out one object "
                "where none of their views from a common size and side differ (one object's sides differ by "
                "up to about 0.16; at least colour_minimum_difference). Also the most by which a newcomer in a "
                "missing anchor's place may differ from it for the reappearance to be left undecided rather "
                "than decided by colour.", 0.001, 0.999),
        Setting("colour_place_radius", ("core", "colour", "place_radius"),
                "How near (m, horizontally) to an anchor one whole view must stand for its colour to count "
                "against it, nearer to no other anchor of its class (a view elsewhere is another object, or "
                "the object moved: the matcher and the merges judge those).", 0.01, 100.0),
        Setting("colour_second_view_after", ("core", "colour", "second_view_after"),
                "Seconds after a first whole view of another colour (left unresolved: no new anchor, and not "
                "the anchor's) that a second one must come to rule the anchor out; 0: the first one does.",
                0.0, 60.0),
        Setting("far_view_scale_ratio", ("core", "far_view", "scale_ratio"),
                "A view whose box (square root of its area) is under this share of every view in an anchor's "
                "appearance gallery is too far to compare with it: unmatched, it is left unresolved (no new "
                "anchor) rather than anchored anew, if that anchor scored it at least far_view_score_floor and "
                "nothing else reacquired it (appearance matchers only; 0 turns it off).", 0.0, 0.99),
        Setting("far_view_score_floor", ("core", "far_view", "score_floor"),
                "A matching score under this is a firm \"another object\", acted on whatever the view's size.",
                0.0, 0.99),
    ),
    *_group(
        "Frame registration (the pose error a frame's percepts share)",
        Setting("registration_maximum_offset", ("core", "registration", "maximum_offset"),
                "The largest pose error (m) looked for: before matching, the one horizontal offset that puts "
                "the most of a frame's whole views on settled anchors of their class is added to every "
                "percept of the frame (0 turns it off).", 0.0, 5.0),
        Setting("registration_inlier_radius", ("core", "registration", "inlier_radius"),
                "How close (m, horizontally) a shifted percept must come to an anchor of its class to "
                "count for an offset.", 0.0, 1.0),
        Setting("registration_minimum_support", ("core", "registration", "minimum_support"),
                "How many percepts an offset must put on anchors to be applied (it must also put more "
                "there than no offset does, and more than twice as many as any rival offset; where no "
                "offset puts more there than none, the error those views share is taken out; a frame "
                "off its anchors that reads two ways has those views held out of matching).", 2, 1000),
        Setting("registration_minimum_views", ("core", "registration", "minimum_views"),
                "How many times an anchor must have been seen to serve as a landmark for the offset.", 1, 1000000),
    ),
    *_group(
        "Spatial index (performance only)",
        Setting("index_tolerance", ("core", "index", "tolerance"),
                "How far (m) an anchor may drift before it is re-indexed.", 0.0, 100.0),
        Setting("index_rebuild_minimum", ("core", "index", "rebuild_minimum"),
                "Pending anchors that trigger a rebuild of the k-d tree, at least.", 1, 1000000),
        Setting("index_rebuild_fraction", ("core", "index", "rebuild_fraction"),
                "Fraction of the anchors pending that triggers a rebuild of the k-d tree.", 0.001, 1.0),
    ),
    *_group(
        "Persistence: the knowledge base and the state on disk, off the perception hot path",
        Setting("knowledge_base", ("persistence", "knowledge_base"),
                "Knowledge base the anchors are synced into, by diff: ros:///merlin2 (the knowledge_base "
                "node), kant+ros:///merlin2 (KANT's node, MERLIN2's knowledge base), sqlite:///path, "
                "mongodb://host/db, memory, or \"\" for none.", deployment=True),
        Setting("grounding", ("persistence", "grounding"),
                "Grounding relation (class -> type, waypoints, predicates); \"\" uses config/grounding.yaml.",
                deployment=True),
        Setting("state_folder", ("persistence", "state_folder"),
                "Where anchors and symbol counters are saved so they survive a restart; \"\" starts afresh.",
                deployment=True),
        Setting("sync_period", ("persistence", "sync_period"),
                "Seconds between knowledge-base syncs.", 0.05, 60.0),
        Setting("save_period", ("persistence", "save_period"),
                "Seconds between saves of the anchors.", 0.1, 3600.0),
        Setting("knowledge_base_timeout", ("persistence", "knowledge_base_timeout"),
                "Seconds one knowledge-base call may wait for an answer before the sync is retried (the "
                "worker saves nothing while it waits).", 0.1, 60.0),
    ),
    *_group(
        "Node timing",
        Setting("track_period", ("timing", "track_period"),
                "Seconds between Track steps (expected effects, carried objects, forgetting).", 0.05, 60.0),
        Setting("stamp_tolerance", ("timing", "stamp_tolerance"),
                "Largest gap (s) between the percepts and the camera pose / depth image they are judged "
                "with; without a pose that close, no anchor is marked missing that frame.", 0.0, 1.0),
        Setting("frame_backlog", ("timing", "frame_backlog"),
                "Percept arrays kept waiting while the node anchors a frame (1: only the newest); beyond it "
                "the oldest is dropped and counted. A few frames let a burst of new objects (each crop to "
                "embed) be caught up on instead of losing the sightings that confirm them; the price is "
                "latency during the burst.", 1, MAXIMUM_FRAME_BACKLOG),
        Setting("pose_source", ("inputs", "pose_source"),
                "Camera pose from topic (PoseStamped on camera_pose, the optical frame in world_frame) or from "
                "tf (TF through tf2_ros: the camera info's frame in world_frame at each percept stamp; a frame "
                "without that transform is dropped, counted and logged).", choices=POSE_SOURCES),
    ),
)

SETTINGS_BY_NAME: Mapping[str, Setting] = MappingProxyType({row.name: row for row in SETTINGS})


def parameter_values(settings: AnchoringSettings) -> dict[str, Any]:
    """Every parameter's value in ``settings``, by name (for reports, and the inverse of loading)."""
    return {row.name: value_at(settings, row.path) for row in SETTINGS}


def settings_from_parameters(
    values: Mapping[str, Any], sources: Mapping[str, str] | None = None
) -> AnchoringSettings:
    """The defaults with ``values`` (parameter name -> value) applied; ``sources`` says where each
    value came from, for the error messages.

    Every value is checked against its row, then the changed fields are set dataclass by
    dataclass, each rebuilt once with all its changes (so that two fields checked together, like
    the rules' two sigmas, are set together) and validated by its own ``__post_init__``.
    """
    changes: dict[str, Any] = {}
    for name, value in values.items():
        source = (sources or {}).get(name, "the given values")
        row = SETTINGS_BY_NAME.get(name)
        if row is None:
            close = difflib.get_close_matches(name, SETTINGS_BY_NAME, n=1)
            raise ConfigurationError(
                f"unknown anchoring parameter '{name}' in {source}"
                + (f"; did you mean '{close[0]}'?" if close else "; see config/anchoring.yaml"))
        row.check(value, source)
        branch = changes
        for step in row.path[:-1]:
            branch = branch.setdefault(step, {})
        branch[row.path[-1]] = value
    try:
        return _with_changes(default_settings(), changes)
    except ConfigurationError as error:
        raise ConfigurationError(f"anchoring settings from {_describe(sources)}: {error}") from error


def _with_changes(instance: Any, changes: Mapping[str, Any]) -> Any:
    if not changes:
        return instance
    fields = {
        name: _with_changes(getattr(instance, name), change) if isinstance(change, dict) else change
        for name, change in changes.items()
    }
    return dataclasses.replace(instance, **fields)


def _describe(sources: Mapping[str, str] | None) -> str:
    named = sorted(set((sources or {}).values()))
    return ", ".join(named) if named else "the given values"


# --- ROS parameter files --------------------------------------------------------------------


def load_anchoring_settings(
    *sources: str | os.PathLike[str] | Mapping[str, Any],
    overrides: Mapping[str, Any] | None = None,
    node: str = f"/{NODE_NAME}",
) -> AnchoringSettings:
    """The settings a node named ``node`` (fully qualified) would be started with.

    ``sources`` are, in order, ROS parameter files (the ``ros__parameters`` of every section whose
    node name matches ``node``: ``/**/anchoring``, ``anchoring``, ``/**``, nested namespaces...) and
    mappings of values (a launch file's inline parameters); later values win, then ``overrides``.
    A file's section for this node must name only known parameters; a section for every node
    (``/**``) may carry other nodes' parameters too, which are skipped.
    """
    values: dict[str, Any] = {}
    origins: dict[str, str] = {}
    for source in sources:
        if isinstance(source, Mapping):
            values.update(source)
            origins.update(dict.fromkeys(source, "inline parameters"))
            continue
        for name, value in read_parameter_file(source, node).items():
            values[name] = value
            origins[name] = str(source)
    for name, value in (overrides or {}).items():
        values[name] = value
        origins[name] = "the overrides"
    return settings_from_parameters(values, origins)


def read_parameter_file(path: str | os.PathLike[str], node: str = f"/{NODE_NAME}") -> dict[str, Any]:
    """The anchoring parameters a ROS parameter file gives the node ``node``, later sections winning
    (as rcl reads them). Parameters of other nodes in a section for every node are left out."""
    path = Path(path).expanduser()
    try:
        document = yaml.safe_load(path.read_text())
    except OSError as error:
        raise ConfigurationError(f"cannot read the parameter file {path}: {error}") from error
    except yaml.YAMLError as error:
        raise ConfigurationError(f"{path} is not valid YAML: {error}") from error
    if document is None:
        return {}
    if not isinstance(document, dict):
        raise ConfigurationError(f"{path} must map node names to {{ros__parameters: ...}} sections")
    target = [token for token in node.split("/") if token]
    values: dict[str, Any] = {}
    for pattern, parameters in _sections(document, [], path):
        if not _node_matches(pattern, target):
            continue
        own = bool(pattern) and pattern[-1] == target[-1]
        for name, value in _flatten(parameters, ""):
            if own or name in SETTINGS_BY_NAME:
                values[name] = value
    return values


def _sections(document: Mapping[Any, Any], prefix: list[str], path: Path) -> Iterator[tuple[list[str], Any]]:
    """(node name tokens, ros__parameters) of every section, in file order; namespaces may nest."""
    for key, body in document.items():
        tokens = prefix + [token for token in str(key).split("/") if token]
        if not isinstance(body, dict):
            raise ConfigurationError(f"{path}: '{key}' must hold a ros__parameters mapping")
        if "ros__parameters" in body:
            parameters = body["ros__parameters"] or {}
            if not isinstance(parameters, dict):
                raise ConfigurationError(f"{path}: the ros__parameters of '{key}' must be a mapping")
            yield tokens, parameters
        else:
            yield from _sections(body, tokens, path)


def _node_matches(pattern: list[str], name: list[str]) -> bool:
    """rcl's node-name wildcards: ``*`` is one token, ``**`` any number of them (none too)."""
    if not pattern:
        return not name
    if pattern[0] == "**":
        return any(_node_matches(pattern[1:], name[skip:]) for skip in range(len(name) + 1))
    if not name:
        return False
    return pattern[0] in ("*", name[0]) and _node_matches(pattern[1:], name[1:])


def _flatten(parameters: Mapping[Any, Any], prefix: str) -> Iterator[tuple[str, Any]]:
    """ROS nests parameter names with mappings (``a: {b: 1}`` is ``a.b``)."""
    for key, value in parameters.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            yield from _flatten(value, f"{name}.")
        else:
            yield name, value


# --- config/anchoring.yaml from the table ---------------------------------------------------

_FILE_HEADER = """\
# Parameters of the anchoring node (merlin2_sailor.ros.anchoring_node): percepts in; anchors,
# anchor events, markers and knowledge-base facts out. `sailor replay`, `sailor evaluate` and the
# benchmarks read this file too (merlin2_sailor.anchoring.settings), so they run the same system.
# Every value here is the default of merlin2_sailor/anchoring/settings.py's table, which also gives
# each its range; `python -m merlin2_sailor.anchoring.settings` prints this file from it.
# Topics in: percepts (PerceptArray), color/camera_info, camera_pose (PoseStamped, optical frame in
# world_frame; or /tf and /tf_static with pose_source tf), depth/image_raw (optional, enables the
# occlusion test), robot_pose (PoseStamped, for carried objects). Out: anchors (AnchorArray,
# latched), anchor_events (AnchorEventArray), anchor_markers (MarkerArray). Services:
# ~/get_anchors, ~/find_anchor, ~/forget_anchor, ~/expect_anchor.
"""


def render_parameter_file() -> str:
    """config/anchoring.yaml as the table documents it: every row, its description, range and default."""
    lines = [_FILE_HEADER.rstrip("\n"), f"/**/{NODE_NAME}:", "  ros__parameters:"]
    group = None
    for row in SETTINGS:
        if row.group != group:
            group = row.group
            lines.append(f"    # --- {group} ---")
        text = row.description + (f" ({row.range_text})" if row.range_text else "")
        lines += textwrap.wrap(text, width=100, initial_indent="    # ", subsequent_indent="    # ")
        value = yaml.safe_dump(row.default, default_flow_style=True).strip().removesuffix("...").strip()
        lines.append(f"    {row.name}: {value}")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    print(render_parameter_file(), end="")
