"""Colour as evidence against identity: what an anchor's own pixels looked like, and when two differ.

The rules compare class, place and time, and the learned matcher's appearance branch is fooled
by a look-alike of another colour standing where the sought object was (both measured, issue
#14). So a merge of two anchors (a search's find, a reappearance) also asks their colours, which
every matcher can afford: the percept generator reads a colour histogram from the object's own
pixels (:func:`~merlin2_sailor.perception.colour_histogram.object_colour`), and each anchor keeps
a :class:`ColourModel` of its whole views.

Why a test on the bin that differs most, and not a histogram distance: objects of one make share
most of their pixels (the demo's mugs are 75 % coffee and shadow), so two mugs of different colours
still intersect at 0.76-0.85, inside the 0.82-1.0 of one mug's own views. What tells them apart is
the one colour one has and the other lacks (the red mug's 12 % of red, the green mug's 14 % of
green). Hues are compared in windows of three bins (60 degrees), so that a hue sliding across a bin
edge from one view to the next is not a difference. Measured on the demo's house (every object,
a tour at 3 Hz): the largest such difference between an anchor's mean and one of its own whole
views was at most 0.17 (cups; p99 0.11), between the means of two mugs of different colours
0.16-0.23, and between two mugs of one colour at most 0.05.

Two anchors' colours *differ* only when at least one of them has enough whole views to know its
colour (``minimum_views``), and one window differs by more than ``minimum_difference`` *and* by more
than ``noise_factor`` times what the anchors' own views vary by in it (a newcomer with fewer views is
held to the known anchor's spread): evidence, not a hunch. Without it (no anchor known well
enough, no colour at all) nothing is ruled out, as before. Measured on the demo's
house with 3 to 10 random views per anchor (20 draws): no two anchors of one object differed, and
360 of 420 pairs of different mugs did (the other 60: mugs of one colour), 323 of 420 of books.

One whole view can also rule out an anchor, in the matching table, but only for an anchor whose
colour has gone unchecked (no whole view with a colour fused) for ``absence`` seconds: an object is
swapped for a look-alike of another colour while the camera looks elsewhere (the green mug put where
the red one stood), never between two frames, and one view is noisier than an anchor's mean.
Measured on the same tour, a single whole view of an object differed from its anchor in 1-5 % of
views by class, views of other objects of its class in 60-85 %; a view cut by the image's edge or
an occluder differed in up to 60 %, so partial views are never used, nor a view showing clearly less
of a large object than the anchor's whole views did (:func:`.partial_view.smaller_than_known`: a
view of 0.59 m of a 1.68 m bicycle once ruled the bicycle's anchor out; on tours of 20
held-out houses this drops the own objects' returns whose first two views differed from 1 of 325 to
0, and the views of other objects ruled out from 80 % to 78 %). Once a view of another colour
stood in its place, the anchor is *disputed*: while it is MISSING, views that show no colour (far,
cut off) cannot bring it back either, only a view of its own colour can (in the swap, the far views
of the green mug had reacquired the red mug's anchor before a close one showed green). A view
wrongly ruled out makes a new anchor for a while, which the reappearance merge folds back once the
two anchors' colours agree. Measured on tours of the house over three seeds, this costs one or two
duplicate anchors in all (rules: 5 duplicates, was 3; the network: 4, was 3). Where the two anchors'
colours differ by no more than one object's own views do (:func:`anchor_colour_gap`, at most
``minimum_difference_across_sides``), the reappearance is left undecided instead: the lost anchor
names the newcomer it cannot be told from (:meth:`.identity_repair.IdentityRepair.decide_reappearances`).

A single view is compared only with the anchor's views *of about its size* (``comparable_size``:
at most twice as large or small, by the square root of the box's area), kept as one model per
half-octave band of sizes (:class:`ColourBySize`); an anchor with fewer than ``minimum_views`` such
views has no colour to rule the view out by. Why: a view's colour depends on how large it is
seen, not only on what it shows (a far view's few pixels blend the object's outline and edge
colours; a close-up shows parts a far view blurs away). Measured on tours of 20 held-out generated
houses (``scripts/colour_views_by_size.py``; 325 returns to an object after 10 s or more): the first
view of a return differed from the object's own anchor in 19 returns held to all its views, 8 of
them 2.3-4.1 times larger or smaller than the anchor's median view; held to views of about its
size, in 9. A view of another object of the class was ruled out as often either way (80 % of
13,315 tests against all views; 80 % of the 12,094 that had comparable views).
A view that cannot be held to the anchor's colour (none of its views is of about its size) is, for
that anchor, a view without a colour: while the anchor's colour is unchecked it neither checks it
nor joins it (:meth:`~.anchor.Anchor.colour_untellable`); far views of a green mug standing where
the red one was seen close up once reacquired the red anchor and made its colour half green, and
the mission claimed the green mug (`swapped`, rules, seed 0). While the colour is fresh, views of
every size join it, so an object approached fills its sizes in. Merges compare two anchors' whole
models (their means over many views are not one view), side by side where they can (below).

A single view is also held only to the anchor's views *from about its side* (``comparable_bearing``:
the views whose bearing, the horizontal direction from the object to the camera, lies within that
many degrees of the view's, kept by sectors of 45 degrees). Why: an object's colour is not the
same from every side (a dog's flank and its face, a bird's back and its breast, the front and
the back of anything printed), and a view from a side the anchor never saw is no evidence that
it is another object. Measured in the scenario suite's probes of 5 December 2026: a large
many-coloured object seen again from another side (the kitchen's dog, the living room's bird, the
bedroom's dog) had its view ruled out by colour 0.03-0.05 m from its own anchor, and got a
second anchor. A look-alike put in an object's place is seen from where the object was seen (the
robot comes back by the same waypoints), so it is still ruled out. A view whose bearing is not
known (no camera pose) is held to all sides, as before.

Two anchors are also held to each other side by side (:func:`anchor_colours_differ`, what every
merge rule asks): their whole models are the means of whichever sides each happened to see. Where
they differ, the difference counts when their views of about one size from about one side (the
windows a single view is held to) differ too; where no such views of the two differ (most anchors
of a house are seen from one side only, so often there are none to compare), it counts only above
``minimum_difference_across_sides``: more than one object's two sides differ by. Measured on tours
of 20 held-out generated houses (``scripts/colour_across_sides.py``: sides more than 60 degrees
apart at about one size, 3 or more whole views each): one object's two sides differed by at most
0.17 (p95 0.088, p99 0.156; 71 pairs), two objects' sides by a median of 0.42 (938 pairs); over
0.10, 4.2 % of one object's pairs of sides would have been taken for two objects, over 0.16, 1.4 %,
while 85 % and 80 % of two objects' pairs were told apart. Why: the bicycle of
`large_object_wheeled_away` (network, seed 2, 6 December 2026), known from 40 views of one end and
anchored anew from two views of its other side where it was wheeled to, differed from itself by
0.116; the search ruled its only candidate out and the mission ended "not found" with the bicycle
anchored twice. In the same suite, the 181 pairs of anchors of different objects whose means differ
with no common side differing differed by 0.175 or more.

Every comparison takes the grey pixels' mid and light bins as one window (:func:`lit_alike`):
light changes no hue, but a face turned from or to the light moves its grey pixels between them.
Measured in the scenario suite (6 December 2026, network, seed 0): two red books of one make, one
on a shelf and one on a desk turned another way, differed by 0.28, all of it mid grey gone light,
so the desk's copy was no twin of the shelf's and a search claimed the shelf's
(`removed_while_a_twin_is_unseen`); a shelf book's own view, its neighbour taken away, differed
from its anchor by 0.19 in the mid bin and was held apart from it, and the removed twin's missing
anchor took it (`twin_removed_from_the_shelf`). The dark bin stays apart: a black object is not a
white one in any light. (The figures above were measured with the three bins apart.)

Only a view standing in the anchor's place (within ``place_radius``, 0.5 m, and nearer to it than
to any other anchor of its class: on a shelf, a book's view is not its neighbour's) counts against it: the
matching table's gate reaches 3 m or more, and a view of the hall's book 3 m from the kitchen's
cookbook, of another colour as it should be, once disputed the cookbook's anchor, so that a later
odd view of the cookbook itself ruled it out at once (`swapped`, rules, seed 0, 3 December). A view
elsewhere is another object or the object moved; the matcher and the merges judge those.

And one view is not enough: a first view of another colour only raises a suspicion (the anchor is
not reacquired by it, and the view makes no new anchor: it is left unresolved); a second such view
at least ``second_view_after`` seconds later, while the camera has moved on a little, rules the
anchor out. Measured on the same returns: the first *two* views differed (from views of about their
size) in 1 of 292 returns, against 9 of 325 for the first view alone, at the tours' 3 frames per
second; a view of its own colour in between is fused as usual, and ends the suspicion.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from merlin2_sailor.anchoring.doubling import doubled
from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.perception.colour_histogram import COLOUR_BINS, HUE_BINS

#: A first view of another colour that no second one followed within this many times
#: ``second_view_after`` is forgotten: the two must be close enough in time to be of one visit.
SUSPICION_LIFETIME = 10.0


@dataclass(frozen=True, slots=True)
class ColourEvidenceConfig:
    """``minimum_views``: whole views an anchor needs before its colour is known (one of the two
    compared must know it; 0 turns the evidence off); ``minimum_difference``: the share of the
    object's pixels by which one colour window must differ (0..1); ``noise_factor``: how many
    standard deviations of the two anchors' own views the difference must also exceed;
    ``absence`` (s): how long an anchor's colour must have gone unchecked before one view of
    another colour rules it out; ``comparable_size``: how many times larger or smaller (square
    root of the box's area) the anchor's views may be than a single view they are compared with;
    ``second_view_after`` (s): how long after a first view of another colour a second one must
    come before they rule the anchor out (0: the first one does); ``place_radius`` (m): how near
    (horizontally) to the anchor a single view must stand for its colour to count against it
    (nearer to no other anchor of its class, too); ``comparable_bearing`` (degrees): how far the
    bearings of the anchor's views (object to camera, horizontally) may be from a single view's
    (180: every side); ``minimum_difference_across_sides``: the share by which two anchors' whole
    colours must differ to rule out one object where none of their views from a common size and
    side differ (see the module docstring)."""

    minimum_views: int = 3
    minimum_difference: float = 0.1
    noise_factor: float = 3.0
    absence: float = 10.0
    comparable_size: float = 2.0
    second_view_after: float = 0.3
    place_radius: float = 0.5
    comparable_bearing: float = 60.0
    minimum_difference_across_sides: float = 0.16

    def __post_init__(self) -> None:
        if self.minimum_views < 0:
            raise ConfigurationError(
                f"anchoring colour_minimum_views must be >= 0 (0 turns colour evidence off), got {self.minimum_views}."
            )
        if not (0.0 < self.minimum_difference < 1.0):
            raise ConfigurationError(
                f"anchoring colour_minimum_difference must be in (0, 1), got {self.minimum_difference}."
            )
        if not (math.isfinite(self.noise_factor) and self.noise_factor >= 0.0):
            raise ConfigurationError(f"anchoring colour_noise_factor must be >= 0, got {self.noise_factor}.")
        if not (math.isfinite(self.absence) and self.absence >= 0.0):
            raise ConfigurationError(f"anchoring colour_absence must be >= 0 seconds, got {self.absence}.")
        if not (math.isfinite(self.comparable_size) and self.comparable_size >= 1.0):
            raise ConfigurationError(
                f"anchoring colour_comparable_size must be >= 1 (a size ratio), got {self.comparable_size}."
            )
        if not (math.isfinite(self.place_radius) and self.place_radius > 0.0):
            raise ConfigurationError(f"anchoring colour_place_radius must be > 0 metres, got {self.place_radius}.")
        if not (math.isfinite(self.comparable_bearing) and 0.0 < self.comparable_bearing <= 180.0):
            raise ConfigurationError(
                f"anchoring colour_comparable_bearing must be in (0, 180] degrees, got {self.comparable_bearing}."
            )
        if not (self.minimum_difference <= self.minimum_difference_across_sides < 1.0):
            raise ConfigurationError(
                "anchoring colour_minimum_difference_across_sides must be in [colour_minimum_difference, 1), "
                f"got {self.minimum_difference_across_sides}."
            )
        if not (math.isfinite(self.second_view_after) and self.second_view_after >= 0.0):
            raise ConfigurationError(
                f"anchoring colour_second_view_after must be >= 0 seconds, got {self.second_view_after}."
            )

    def suspicion_confirmed(self, suspected_since: float | None, stamp: float) -> bool:
        """Whether a view of another colour at ``stamp`` confirms the suspicion raised by one at
        ``suspected_since`` (None: none raised): it came at least ``second_view_after`` later, and
        not so late (more than :data:`SUSPICION_LIFETIME` times that) that the first is stale."""
        if self.second_view_after == 0.0:
            return True
        if suspected_since is None:
            return False
        elapsed = stamp - suspected_since
        return self.second_view_after <= elapsed <= SUSPICION_LIFETIME * self.second_view_after

    def suspicion_stale(self, suspected_since: float | None, stamp: float) -> bool:
        """Whether a suspicion raised at ``suspected_since`` is too old to be confirmed at ``stamp``
        (or there is none): a new view of another colour raises it again."""
        return suspected_since is None or stamp - suspected_since > SUSPICION_LIFETIME * self.second_view_after


def colour_windows(histogram: np.ndarray) -> np.ndarray:
    """(COLOUR_BINS,) float64: each hue bin summed with its two neighbours around the circle, then
    the grey bins as they are."""
    values = np.asarray(histogram, dtype=np.float64)
    if values.shape != (COLOUR_BINS,):
        raise InvalidInputError(f"a colour histogram has {COLOUR_BINS} values, got shape {values.shape}")
    hue = values[:HUE_BINS]
    return np.concatenate([hue + np.roll(hue, 1) + np.roll(hue, -1), values[HUE_BINS:]])


@dataclass(slots=True, eq=False)
class ColourModel:
    """The mean and spread of an anchor's colour windows over its whole views (Welford's running
    sums, so that merging two anchors' models is exact)."""

    views: int
    mean: np.ndarray
    squares: np.ndarray
    """Sum of squared deviations from the mean, per window."""

    @classmethod
    def of(cls, histogram: np.ndarray) -> ColourModel:
        return cls(1, colour_windows(histogram), np.zeros(COLOUR_BINS))

    def add(self, histogram: np.ndarray) -> None:
        windows = colour_windows(histogram)
        self.views += 1
        delta = windows - self.mean
        self.mean = self.mean + delta / self.views
        self.squares = self.squares + delta * (windows - self.mean)

    def copy(self) -> ColourModel:
        return ColourModel(self.views, self.mean.copy(), self.squares.copy())

    def merged(self, other: ColourModel) -> ColourModel:
        views = self.views + other.views
        delta = other.mean - self.mean
        mean = self.mean + delta * (other.views / views)
        squares = self.squares + other.squares + delta * delta * (self.views * other.views / views)
        return ColourModel(views, mean, squares)

    @property
    def variance(self) -> np.ndarray:
        return self.squares / max(self.views - 1, 1)


def with_view(model: ColourModel | None, histogram: np.ndarray | None) -> ColourModel | None:
    """``model`` after one more whole view's colour (None: the view had none)."""
    if histogram is None:
        return model
    if model is None:
        return ColourModel.of(histogram)
    model.add(histogram)
    return model


def combined(first: ColourModel | None, second: ColourModel | None) -> ColourModel | None:
    """Both models as one (an anchor merged into another)."""
    if first is None or second is None:
        known = first or second
        return None if known is None else known.copy()
    return first.merged(second)


def _compared_with_noise(first: ColourModel | None, second: ColourModel | None, config: ColourEvidenceConfig
                         ) -> tuple[ColourModel, ColourModel, np.ndarray] | None:
    """Both models as every comparison takes them (:func:`lit_alike`), with the noise a window's
    difference must exceed (``noise_factor`` standard deviations of both sides' views; a side with
    fewer than ``minimum_views`` views held to the known side's spread); None where nothing can be
    told: evidence off, a side without colour, or neither side knowing its colour."""
    if config.minimum_views == 0 or first is None or second is None:
        return None
    first, second = lit_alike(first), lit_alike(second)
    first_known, second_known = first.views >= config.minimum_views, second.views >= config.minimum_views
    if not (first_known or second_known):
        return None
    first_variance = first.variance if first_known else second.variance
    second_variance = second.variance if second_known else first.variance
    return first, second, config.noise_factor * np.sqrt(first_variance + second_variance)


def colour_difference(first: ColourModel | None, second: ColourModel | None, config: ColourEvidenceConfig) -> float:
    """The largest window difference that counts as evidence (see the module docstring), or 0.0
    when there is none: no colour on either side, neither side with ``minimum_views`` (nobody
    knows the colour yet), or every difference within the noise. A side with fewer views (a
    newcomer, one view) is held to the known side's spread: its own few views cannot say how much
    the object's colour varies."""
    compared = _compared_with_noise(first, second, config)
    if compared is None:
        return 0.0
    first, second, noise = compared
    difference = np.abs(first.mean - second.mean)
    counted = (difference > config.minimum_difference) & (difference > noise)
    return float(difference[counted].max()) if counted.any() else 0.0


def colours_differ(first: ColourModel | None, second: ColourModel | None, config: ColourEvidenceConfig) -> bool:
    """Whether the two anchors' colours show they are different objects."""
    return colour_difference(first, second, config) > 0.0


def colours_agree(first: ColourModel | None, second: ColourModel | None, config: ColourEvidenceConfig) -> bool:
    """Whether both anchors know their colour (``minimum_views`` whole views each) and the colours
    do not differ: evidence *for* one object, as a relocation merge needs (not knowing is no
    evidence either way)."""
    if config.minimum_views == 0 or first is None or second is None:
        return False
    if first.views < config.minimum_views or second.views < config.minimum_views:
        return False
    return not colours_differ(first, second, config)


def lit_alike(model: ColourModel | None) -> ColourModel | None:
    """The model with its mid and light grey windows summed into the light one (the mid one empty),
    as every comparison takes it (see the module docstring); their spreads are added, the larger of
    what their sum can vary by."""
    if model is None:
        return None
    mid, light = HUE_BINS + 1, HUE_BINS + 2
    mean, squares = model.mean.copy(), model.squares.copy()
    mean[light], mean[mid] = mean[mid] + mean[light], 0.0
    squares[light], squares[mid] = squares[mid] + squares[light], 0.0
    return ColourModel(model.views, mean, squares)


def colour_evidence_grew(model: ColourModel | None, minimum_views: int) -> bool:
    """Whether the latest view made the colour known (``minimum_views`` views) or doubled its views
    since (2, 4, 8... times as many): when an identity decided on colour is worth judging again."""
    return model is not None and doubled(model.views, minimum_views)


def view_differs(model: ColourModel | None, histogram: np.ndarray | None, config: ColourEvidenceConfig) -> bool:
    """Whether one whole view's colour differs from ``model``'s (of views of about its size: see
    :func:`sized_view_differs`)."""
    return histogram is not None and colours_differ(model, ColourModel.of(histogram), config)


#: Bands of view sizes per octave (each band spans a factor of the square root of 2).
SIZE_BANDS_PER_OCTAVE = 2
#: Sectors of bearing (object to camera, horizontally) around an object: 45 degrees each.
BEARING_SECTORS = 8


def size_band(size: float) -> int:
    """The band of a view of ``size`` pixels (the square root of its box's area; > 0)."""
    return math.floor(math.log2(size) * SIZE_BANDS_PER_OCTAVE)


def band_centre(band: int) -> float:
    """The geometric middle of a band's sizes, in pixels."""
    return 2.0 ** ((band + 0.5) / SIZE_BANDS_PER_OCTAVE)


def bearing_sector(bearing: float | None) -> int | None:
    """The sector of a bearing in radians (None, or not finite: not known)."""
    if bearing is None or not math.isfinite(bearing):
        return None
    return math.floor((bearing % math.tau) / (math.tau / BEARING_SECTORS)) % BEARING_SECTORS


def sector_centre(sector: int) -> float:
    """The middle of a sector's bearings, in radians."""
    return (sector + 0.5) * math.tau / BEARING_SECTORS


def bearing_gap(first: float, second: float) -> float:
    """The angle between two bearings, in radians (0..pi)."""
    gap = abs(first - second) % math.tau
    return min(gap, math.tau - gap)


ViewKey = tuple[int, int | None]
"""(size band, bearing sector or None where the bearing was not known)."""


@dataclass(slots=True, eq=False)
class ColourBySize:
    """An anchor's whole views' colours, one :class:`ColourModel` per band of view sizes and sector
    of bearings, so that a single view is held only to views of about its size, seen from about
    its side (see the module docstring). Bounded: a view adds to one of a few dozen bands times
    eight sectors, never a new entry each."""

    bands: dict[ViewKey, ColourModel] = field(default_factory=dict)

    def add(self, histogram: np.ndarray, size: float, bearing: float | None = None) -> None:
        """One more whole view's colour; a view without a size (an empty box) has no band and is
        left out; ``bearing`` (radians, object to camera): None where not known."""
        if not (math.isfinite(size) and size > 0.0):
            return
        key = (size_band(size), bearing_sector(bearing))
        model = self.bands.get(key)
        if model is None:
            self.bands[key] = ColourModel.of(histogram)
        else:
            model.add(histogram)

    def comparable(self, size: float, ratio: float, bearing: float | None = None,
                   bearing_window: float = 180.0) -> ColourModel | None:
        """The views whose band's middle is at most ``ratio`` times larger or smaller than ``size``
        and, where both bearings are known, whose sector's middle is at most ``bearing_window``
        degrees from ``bearing``, as one model (None: none)."""
        if not (math.isfinite(size) and size > 0.0):
            return None
        window = math.radians(bearing_window)
        known = bearing is not None and math.isfinite(bearing)
        chosen = [model for (band, sector), model in self.ordered()
                  if size / ratio <= band_centre(band) <= size * ratio
                  and (not known or sector is None or bearing_gap(sector_centre(sector), bearing) <= window)]
        if not chosen:
            return None
        result = chosen[0].copy()
        for model in chosen[1:]:
            result = result.merged(model)
        return result

    def ordered(self) -> list[tuple[ViewKey, ColourModel]]:
        """The bands in a fixed order (sums and snapshots the same on every run)."""
        return sorted(self.bands.items(), key=lambda item: view_key_order(item[0]))

    def merged(self, other: ColourBySize) -> ColourBySize:
        """Both anchors' views, band by band (an anchor merged into another)."""
        bands = {key: model.copy() for key, model in self.bands.items()}
        for key, model in other.bands.items():
            bands[key] = bands[key].merged(model) if key in bands else model.copy()
        return ColourBySize(bands)


def view_key_order(key: ViewKey) -> tuple[int, int]:
    """Bands in a fixed order (sums in a fixed order: the same result on every run)."""
    band, sector = key
    return band, -1 if sector is None else sector


def view_key_text(key: ViewKey) -> str:
    """A snapshot's name for a band: ``"10"`` (bearing not known) or ``"10/3"``."""
    band, sector = key
    return str(band) if sector is None else f"{band}/{sector}"


def view_key_from_text(text: str) -> ViewKey:
    """The band :func:`view_key_text` named (a snapshot written before bearings has sizes only)."""
    band, _, sector = str(text).partition("/")
    return int(band), int(sector) if sector else None


def with_sized_view(model: ColourBySize | None, histogram: np.ndarray | None, size: float,
                    bearing: float | None = None) -> ColourBySize | None:
    """``model`` after one more whole view's colour, seen ``size`` pixels large from ``bearing``
    (None: no colour)."""
    if histogram is None:
        return model
    model = model if model is not None else ColourBySize()
    model.add(histogram, size, bearing)
    return model


def combined_by_size(first: ColourBySize | None, second: ColourBySize | None) -> ColourBySize | None:
    """Both anchors' sized colours as one (an anchor merged into another)."""
    if first is None or second is None:
        known = first or second
        return None if known is None else known.merged(ColourBySize())
    return first.merged(second)


def sized_view_differs(model: ColourBySize | None, histogram: np.ndarray | None, size: float,
                       config: ColourEvidenceConfig, bearing: float | None = None) -> bool:
    """Whether one whole view's colour, seen ``size`` pixels large from ``bearing``, shows it is
    not the anchor's object: it differs from the anchor's views of about its size
    (``comparable_size``) and side (``comparable_bearing``), of which there must be
    ``minimum_views`` (fewer: nothing to tell by, so nothing is ruled out)."""
    if histogram is None or model is None:
        return False
    return view_differs(comparable_views_of(model, size, bearing, config), histogram, config)


def view_gap_text(model: ColourBySize | None, histogram: np.ndarray | None, size: float,
                  config: ColourEvidenceConfig, bearing: float | None = None) -> str:
    """``"0.14 in the hue window at 120 deg: 0.31 in its 6 views, 0.17 in this one"``: how one whole
    view's colour differs from the anchor's views it is held to (:func:`sized_view_differs`), for a
    log line that must let a wrong ruling be traced to its numbers; empty when it does not differ."""
    if histogram is None or model is None:
        return ""
    near = comparable_views_of(model, size, bearing, config)
    difference = colour_difference(near, ColourModel.of(histogram), config)
    if near is None or difference <= 0.0:
        return ""
    near, view = lit_alike(near), lit_alike(ColourModel.of(histogram)).mean
    window = int(np.argmax(np.where(np.abs(near.mean - view) >= difference, np.abs(near.mean - view), -1.0)))
    return (f"{difference:.2f} in the {window_name(window)}: {near.mean[window]:.2f} in its {near.views} views, "
            f"{view[window]:.2f} in this one")


def window_name(window: int) -> str:
    """What a colour window of :func:`colour_windows` covers, in words."""
    if window < HUE_BINS:
        return f"hue window at {round(window * 360 / HUE_BINS)} deg"
    return ("dark grey bin", "mid grey bin", "mid and light grey bins")[window - HUE_BINS]


def comparable_views_of(model: ColourBySize, size: float, bearing: float | None,
                        config: ColourEvidenceConfig) -> ColourModel | None:
    """The anchor's views a single view of ``size`` pixels, seen from ``bearing``, is held to."""
    return model.comparable(size, config.comparable_size, bearing, config.comparable_bearing)


class Coloured(Protocol):
    """What :func:`anchor_colours_differ` reads of an anchor: its whole colour model, its views by
    size and side, and whether its box was joined from parts of a large object (:mod:`.parts`)."""

    colour: ColourModel | None
    colour_by_size: ColourBySize | None
    parts_fit: np.ndarray | None


def side_by_side(first: ColourBySize, second: ColourBySize,
                 config: ColourEvidenceConfig) -> Iterator[tuple[ColourModel, ColourModel]]:
    """For every band of sizes and sector of bearings either anchor saw, both anchors' views of
    about that size from about that side (``comparable_size``, ``comparable_bearing``, as a single
    view is held to), where both have some; one at a time, so a caller looking for one that
    differs stops there."""
    for band, sector in sorted(set(first.bands) | set(second.bands), key=view_key_order):
        bearing = None if sector is None else sector_centre(sector)
        own = first.comparable(band_centre(band), config.comparable_size, bearing, config.comparable_bearing)
        other = second.comparable(band_centre(band), config.comparable_size, bearing, config.comparable_bearing)
        if own is not None and other is not None:
            yield own, other


def anchor_colours_differ(first: Coloured, second: Coloured, config: ColourEvidenceConfig) -> bool:
    """Whether two anchors' colours show they are different objects: their whole models differ, and
    so do their views from a common size and side, or else the whole models differ by more than
    ``minimum_difference_across_sides`` (see the module docstring). Anchors that kept no views by
    size and side (restored from an older snapshot) are held to their whole models. An anchor whose
    box was joined from parts of a large object is no colour evidence, as a part's view is not: its
    views are of whichever faces its parts showed (the wheeled bicycle's joined anchor, seen from
    the side its lost anchor was known from but four times closer, differed from it by 0.185:
    `large_object_wheeled_away`, network, seed 2, 6 December 2026; the matching function compares
    such an anchor without its look for the same reason, :mod:`.anchor_comparison`)."""
    return next(_differences_that_count(first, second, config), None) is not None


def part_shows_a_colour_the_whole_lacks(part: Coloured, whole: Coloured, config: ColourEvidenceConfig) -> bool:
    """Whether ``part``, an anchor of a part of a large object (:mod:`.parts`), cannot be of the
    object ``whole`` is an anchor of by its colour: it shows more of some colour window than the
    whole one does, beyond ``minimum_difference`` and the noise, where the whole one shows less
    than ``minimum_difference`` of that colour. Nothing else of its colour is evidence: a part
    shows only some of its object's faces, so its colours come in other shares than the whole's (a
    bicycle's part, its tyre's black twice the whole bicycle's share and its frame's orange half,
    differed from the bicycle by 0.20, and :func:`anchor_colours_differ` held them apart:
    `moved_to_the_far_room`, network, seed 0, 7 December 2026), but it shows nothing the object
    lacks (a red bicycle's part is not of a blue bicycle). As in :func:`colour_difference`, one of
    the two must know its colour (``minimum_views``), and a side with fewer views is held to the
    known side's spread."""
    if part.parts_fit is not None or whole.parts_fit is not None:
        return False
    compared = _compared_with_noise(part.colour, whole.colour, config)
    if compared is None:
        return False
    part_model, whole_model, noise = compared
    excess = part_model.mean - whole_model.mean
    foreign = (excess > config.minimum_difference) & (excess > noise) & (whole_model.mean < config.minimum_difference)
    return bool(foreign.any())


def anchor_colour_gap(first: Coloured, second: Coloured, config: ColourEvidenceConfig) -> float:
    """By how much two anchors' colours differ where :func:`anchor_colours_differ` says they do
    (the largest difference that counts), else 0.0: how strong the evidence is, for a rule that
    weighs it (:meth:`.identity_repair.IdentityRepair.decide_reappearances`)."""
    return max(_differences_that_count(first, second, config), default=0.0)


def _differences_that_count(first: Coloured, second: Coloured, config: ColourEvidenceConfig) -> Iterator[float]:
    """The differences between two anchors' colours that show they are different objects, one at a
    time (a caller asking only whether there is one stops at the first): those of their views from
    each common size and side, or, where none of those differ, their whole models' above
    ``minimum_difference_across_sides``; nothing unless their whole models differ."""
    if first.parts_fit is not None or second.parts_fit is not None:
        return
    difference = colour_difference(first.colour, second.colour, config)
    if difference == 0.0:
        return
    if first.colour_by_size is None or second.colour_by_size is None:
        yield difference
        return
    sides_differ = False
    for own, other in side_by_side(first.colour_by_size, second.colour_by_size, config):
        side = colour_difference(own, other, config)
        if side > 0.0:
            sides_differ = True
            yield side
    if not sides_differ and difference > config.minimum_difference_across_sides:
        yield difference
