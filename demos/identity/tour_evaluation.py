"""Score matchers on a tour of a simulated house: duplicates and identity switches, side by side.

Every matcher gets its own :class:`~merlin2_sailor.anchoring.anchoring.Anchoring`, configured as
the demo's anchoring node configures it, and all of them are fed the same frames of one
:class:`~.tour.Tour` in lockstep, so the comparison is exact: same frames, same noise, same
detections. Two kinds of figures:

- the demo's scorecard (:mod:`merlin2_sailor_demos.report.scorecard`): after the tour, anchors
  are associated with the true objects (Hungarian, same class, within 0.5 m) and unmatched ones
  near an object of their class are duplicates; the association is recorded after every frame,
  so an object whose symbol changes counts an identity switch;
- from each percept's true object (its instance mask): ``split_objects`` is how many objects were
  given more than one symbol over the tour (one object, two anchors at some point), and
  ``merged_symbols`` how many symbols were given percepts of more than one object (two objects,
  one anchor), which position-based association cannot see when the two are near each other.
"""

from __future__ import annotations

import dataclasses
import time
from collections import Counter, defaultdict
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Protocol

from merlin2_sailor.anchoring.anchoring import Anchoring, AnchoringConfig, AnchoringResult
from merlin2_sailor.anchoring.lifecycle import LifecycleConfig
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.anchoring.matching_table import Embedder
from merlin2_sailor.anchoring.visibility import VisibilityConfig
from merlin2_sailor_demos.identity.tour import Tour, TourConfig, TourFrame, true_objects
from merlin2_sailor_demos.report.scorecard import AnchorRecord, IdentityHistory, Scorecard, associate, score
from merlin2_sailor_demos.world.world import World
from merlin2_sailor_demos.world.world_file import WorldDescription

#: Anchor states that claim an object exists (the scorecard's).
_CLAIMING = ("confirmed", "missing")

#: How often (s) the anchoring node runs Track by default (its ``track_period``).
TRACK_PERIOD = 0.5


def demo_anchoring_config(maximum_depth: float = 4.5) -> AnchoringConfig:
    """The anchoring core as the demo's node configures it (config/anchoring.yaml, launch/demo.yaml)."""
    visibility = VisibilityConfig()
    return AnchoringConfig(
        lifecycle=LifecycleConfig(forget_after=600.0, forget_tentative_after=2.0),
        visibility=dataclasses.replace(visibility, frustum=dataclasses.replace(visibility.frustum, far=maximum_depth)),
    )


@dataclass(frozen=True, slots=True)
class MatcherSetup:
    """One contender: a matcher, and the embedder it needs when it uses appearance."""

    matcher: Matcher
    embedder: Embedder | None = None


@dataclass(slots=True)
class TourScore:
    """What one matcher did over the tour (see the module docstring)."""

    scorecard: Scorecard
    split_objects: dict[str, list[str]] = field(default_factory=dict)
    merged_symbols: dict[str, list[str]] = field(default_factory=dict)
    seconds: float = 0.0

    @property
    def duplicates(self) -> int:
        return len(self.scorecard.duplicates)

    @property
    def switches(self) -> int:
        return self.scorecard.total_switches


class FrameObserver(Protocol):
    """Diagnostics that watch the tour: ``before`` sees each frame and the Anchorings before they
    process it, ``after`` what each did with it."""

    def before(self, frame: TourFrame, anchorings: Mapping[str, Anchoring]) -> None: ...

    def after(self, frame: TourFrame, results: Mapping[str, AnchoringResult]) -> None: ...


@dataclass(slots=True)
class _Contender:
    anchoring: Anchoring
    history: IdentityHistory = field(default_factory=IdentityHistory)
    symbols_of_object: dict[str, set[str]] = field(default_factory=lambda: defaultdict(set))
    objects_of_symbol: dict[str, Counter] = field(default_factory=lambda: defaultdict(Counter))
    track_period: float = TRACK_PERIOD
    next_track: float = 0.0
    seconds: float = 0.0

    def feed(self, frame: TourFrame) -> AnchoringResult:
        started = time.perf_counter()
        result = self.anchoring.process(frame.percepts, frame.camera, frame.stamp)
        if frame.stamp >= self.next_track:
            self.anchoring.track(frame.stamp)
            self.next_track = frame.stamp + self.track_period
        self.seconds += time.perf_counter() - started
        for symbol, object_id in zip(result.percept_symbols, frame.object_ids, strict=True):
            if object_id is not None:
                self.symbols_of_object[object_id].add(symbol)
                self.objects_of_symbol[symbol][object_id] += 1
        self.history.record(associate(frame.truth, self.records(claiming_only=True)))
        return result

    def records(self, claiming_only: bool = False) -> list[AnchorRecord]:
        return [AnchorRecord(a.symbol, a.class_name, tuple(float(v) for v in a.position), a.state.value,
                             tuple(a.indistinguishable_from))
                for a in self.anchoring.anchors if not claiming_only or a.state.value in _CLAIMING]

    def score(self, world: World) -> TourScore:
        card = score(true_objects(world), self.records(), history=self.history)
        # A symbol merged into another (a search or a reappearance) is gone: its percepts are the kept one's.
        alive = {anchor.symbol for anchor in self.anchoring.anchors}
        split = {object_id: sorted(symbols & alive) for object_id, symbols in self.symbols_of_object.items()
                 if len(symbols & alive) > 1}
        merged = {symbol: [f"{object_id} x{count}" for object_id, count in objects.most_common()]
                  for symbol, objects in self.objects_of_symbol.items() if len(objects) > 1 and symbol in alive}
        return TourScore(card, split, merged, self.seconds)


def evaluate_tour(
    description: WorldDescription,
    contenders: Mapping[str, Callable[[], MatcherSetup]],
    seed: int = 0,
    tour: TourConfig | None = None,
    config: AnchoringConfig | None = None,
    observer: FrameObserver | None = None,
    track_period: float = TRACK_PERIOD,
) -> dict[str, TourScore]:
    """Drive one tour of ``description`` and score every contender on it (see the module docstring)."""
    tour = tour or TourConfig()
    config = config or demo_anchoring_config(tour.maximum_depth)
    world = World(description, seed=seed, segment=True)
    running = {}
    for name, factory in contenders.items():
        setup = factory()
        running[name] = _Contender(Anchoring(config, setup.matcher, setup.embedder), track_period=track_period)
    anchorings = {name: contender.anchoring for name, contender in running.items()}
    for frame in Tour(world, tour).frames():
        if observer is not None:
            observer.before(frame, anchorings)
        results = {name: contender.feed(frame) for name, contender in running.items()}
        if observer is not None:
            observer.after(frame, results)
    return {name: contender.score(world) for name, contender in running.items()}


def format_tour_table(scores: Mapping[str, TourScore]) -> str:
    """One row per matcher: anchored, duplicates, identity switches, split objects, merged symbols."""
    width = max([len(name) for name in scores] + [8])
    lines = [f"{'':<{width}}  {'anchored':>9} {'duplicates':>10} {'ID sw.':>7} {'split':>6} {'merged':>7} "
             f"{'seconds':>8}"]
    for name, result in scores.items():
        card = result.scorecard
        lines.append(f"{name:<{width}}  {card.anchored:>4d} / {card.objects:<2d} {result.duplicates:>10d} "
                     f"{result.switches:>7d} {len(result.split_objects):>6d} {len(result.merged_symbols):>7d} "
                     f"{result.seconds:>8.1f}")
    for name, result in scores.items():
        card = result.scorecard
        if card.duplicates or card.identity_switches or result.split_objects or result.merged_symbols:
            lines.append(f"{name}: duplicates {list(card.duplicates)}; switches {dict(card.identity_switches)}; "
                         f"split {result.split_objects}; merged {result.merged_symbols}")
    return "\n".join(lines)
