"""The anchor lifecycle: tentative -> confirmed -> missing -> forgotten, and back from missing.

The original SAILOR kept every anchor forever and could not tell "not seen" from "gone". Here an
anchor earns trust by being seen (``confirm_after`` percepts), loses it only when it *should*
have been seen (in the camera frustum and not occluded: the caller decides that) for
``missed_frames_to_missing`` consecutive frames, and is forgotten after ``forget_after`` seconds
missing. Anchors never confirmed are forgotten sooner (``forget_tentative_after`` after they
should have been seen and were not; sightings more than ``confirm_within`` apart do not add up
to a confirmation) and without ever being called missing: most of them are
spurious detections, and announcing them as missing objects (to the knowledge base, to a planner)
would let false positives pile up where they do harm. Reacquiring a missing anchor restores it.

Each function changes one anchor and returns whether its state changed, so the caller emits the
matching event.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.doubling import doubled
from merlin2_sailor.contract.percept import Percept
from merlin2_sailor.errors import ConfigurationError

#: How far (m, horizontally) two sightings of a MISSING anchor's way back may stand apart beyond
#: half the diagonal of the object's footprint: the noise of two views' positions at a search's
#: ranges (a part of a large object is centred up to half its extent off the whole).
RECOVERY_PLACE_SLACK = 0.3


@dataclass(frozen=True, slots=True)
class LifecycleConfig:
    """``confirm_after``: percepts needed to confirm; ``missed_frames_to_missing``: consecutive
    frames an anchor must be expected yet unseen to be marked missing (more than one rides out
    a detector's flicker); ``forget_after`` / ``forget_tentative_after``: seconds missing before a
    confirmed / never-confirmed anchor is forgotten; ``confirm_within``: seconds within which a
    never-confirmed anchor's sightings must follow one another to add up to a confirmation."""

    confirm_after: int = 3
    missed_frames_to_missing: int = 3
    forget_after: float = 600.0
    forget_tentative_after: float = 2.0
    confirm_within: float = 10.0

    def __post_init__(self) -> None:
        if self.confirm_after < 1:
            raise ConfigurationError(f"lifecycle confirm_after must be at least 1 percept, got {self.confirm_after}.")
        if self.missed_frames_to_missing < 1:
            raise ConfigurationError(
                f"lifecycle missed_frames_to_missing must be at least 1, got {self.missed_frames_to_missing}."
            )
        for name in ("forget_after", "forget_tentative_after", "confirm_within"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ConfigurationError(f"lifecycle {name} must be a non-negative number of seconds, got {value}.")


def was_confirmed(anchor: Anchor, config: LifecycleConfig) -> bool:
    """Whether the anchor has ever been seen often enough to be trusted."""
    return anchor.times_seen >= config.confirm_after


def sightings_doubled(anchor: Anchor, config: LifecycleConfig) -> bool:
    """Whether this sighting made the anchor's sightings twice, four times, eight times... what
    confirmed it: when what its views say (its gallery, its colour, its place) has grown enough to
    judge its identity again. Doubling keeps that to a few times in an anchor's life."""
    return anchor.times_seen >= 2 * config.confirm_after and doubled(anchor.times_seen, config.confirm_after)


def sighting_brings_back(anchor: Anchor, config: LifecycleConfig) -> bool:
    """Whether one more sighting (before :func:`after_sighting` counts it) brings a MISSING anchor
    back: its ``confirm_after``-th of this visit."""
    return anchor.recovery_sightings + 1 >= config.confirm_after


def after_sighting(anchor: Anchor, config: LifecycleConfig) -> bool:
    """Update the state after an acquire or reacquire; True when the anchor became CONFIRMED.

    A MISSING anchor comes back only after ``confirm_after`` sightings with no frame in between
    that should have shown it and did not, as a new anchor must earn trust: one false
    detection near its old place must not tell a planner that a lost object is found.
    """
    if anchor.state is AnchorState.MISSING:
        back = sighting_brings_back(anchor, config)
        anchor.recovery_sightings += 1
        if not back:
            return False
        anchor.recovery_sightings = 0
        anchor.state = AnchorState.CONFIRMED
        anchor.lost_after = None
        anchor.lost_at = None
        return True
    if was_confirmed(anchor, config):
        became_confirmed = anchor.state is AnchorState.TENTATIVE
        anchor.state = AnchorState.CONFIRMED
        return became_confirmed
    anchor.state = AnchorState.TENTATIVE
    return False


def before_sighting(anchor: Anchor, percept: Percept, config: LifecycleConfig) -> None:
    """A tentative anchor must earn its confirmation in one visit, and a MISSING one its return: a
    sighting more than ``confirm_within`` after its last one starts its count again. A MISSING
    anchor's way back must also be seen in one place: a sighting farther from the previous one of
    the way back than half the diagonal of the object's footprint plus
    :data:`RECOVERY_PLACE_SLACK` starts it again (:func:`recovery_moved`).

    Why. A tentative anchor is forgotten that long after it should have been seen and was not,
    but one out of view, or judged hidden, is never on that clock: measured in the MERLIN2 mission
    test (CI, 4 December), a false detection of a cup inside a wall, which the wall itself hid
    from the visibility check, stayed tentative for 50 s and was confirmed by the next two false
    detections there, seconds apart: a second cup in KANT. Sightings of a real object come frames
    apart, or a few seconds when the camera sweeps past and back; 10 s keeps every confirmation
    of the held-out house replays (`sailor evaluate`: 170 anchors and 21 switches for the network,
    167 and 20 for the rules, as without it), where 5 s lost some (171 and 25; 167 and 22).

    Its birth starts again too (``first_seen``): what the anchor stands for is decided by the
    sightings that confirm it, and identity repair reads the birth as when its object was first
    there ("two anchors seen side by side at one time are two objects"). A far view of the
    living room's green mug left a tentative anchor that a look-alike of the hall's blue mug,
    moved beside the green one a minute later, confirmed; born before the blue mug was last seen
    in the hall, that anchor could never be the blue mug, and the search for it gave up
    (scenario suite, `moved_while_its_twin_is_watched`, network, seed 2, 5 December 2026).
    """
    stamp = percept.stamp
    if anchor.state is AnchorState.TENTATIVE and stamp - anchor.last_seen > config.confirm_within:
        anchor.times_seen = 0
        anchor.first_seen = stamp
    elif anchor.state is AnchorState.MISSING and stamp - anchor.last_seen > config.confirm_within:
        # The same for a MISSING anchor's way back: its sightings must come in one visit. A search
        # takes a view of the class anywhere in a disc 3 m wide for the sought anchor, and single
        # false detections there, minutes apart and never unseen in between (out of view, or on a
        # wall), brought a lost bicycle back in the middle of the kitchen (scenario suite,
        # `large_object_wheeled_away`, network, seed 0, 6 December 2026).
        anchor.recovery_sightings = 0
    if anchor.state is AnchorState.MISSING:
        if recovery_moved(anchor, percept):
            anchor.recovery_sightings = 0
        anchor.recovery_at = np.asarray(percept.position, dtype=np.float64).copy()


def recovery_moved(anchor: Anchor, percept: Percept) -> bool:
    """Whether ``percept`` stands too far from the previous sighting of a MISSING anchor's way
    back to be of the same object (False where the way back has not begun).

    Why. A search takes a view of the sought class anywhere in a disc 3 m wide, and each sighting
    that the search takes counts towards the anchor's return: two views of the moved bicycle in
    the living room and, 2.5 s later, a false "bicycle" box on the kitchen wall beside the door,
    1.9 m from them, brought the bicycle back on the wall; the search reported it found in the
    kitchen (scenario suite, `large_object_wheeled_away`, network, seed 0, 6 December 2026). One
    object's views in one visit stand together; views of two places are two things, and neither
    has been seen ``confirm_after`` times."""
    if anchor.recovery_sightings == 0 or anchor.recovery_at is None:
        return False
    offset = np.asarray(percept.position, dtype=np.float64)[:2] - anchor.recovery_at[:2]
    extent = max(float(np.hypot(*anchor.size[:2])), float(np.hypot(*np.asarray(percept.size)[:2])))
    return float(np.hypot(*offset)) > extent / 2.0 + RECOVERY_PLACE_SLACK


def after_expected_but_unseen(anchor: Anchor, stamp: float, config: LifecycleConfig) -> bool:
    """Count one frame in which the anchor should have been seen; True when it became MISSING.

    A tentative anchor never becomes MISSING: it only starts the clock that forgets it.
    """
    if anchor.state is AnchorState.MISSING:
        anchor.recovery_sightings = 0  # sightings must be near in time to bring it back
        return False
    anchor.missed_frames += 1
    if anchor.missed_frames < config.missed_frames_to_missing:
        return False
    if anchor.missing_since is None:
        anchor.missing_since = stamp
    if anchor.state is AnchorState.TENTATIVE:
        return False
    anchor.state = AnchorState.MISSING
    # Lost after the sighting that last placed it, where it is lost at: a part of it seen since (a
    # box cut by the image's edge) kept it alive without moving it, and says too little of what was
    # there to rule out that the object had gone. The bicycle's anchor in the bedroom took such a
    # view 19 s after the bicycle, wheeled into the living room, was anchored anew there: counted
    # as its last sighting, the two "stood together" and the search for it found nothing
    # (scenario suite, `large_object_wheeled_away`, network, seed 1, 6 December 2026).
    anchor.lost_after = anchor.place_seen
    anchor.lost_at = anchor.perceived_position.copy()
    return True


def expire(anchor: Anchor, stamp: float, config: LifecycleConfig) -> bool:
    """Forget a missing anchor once it has been missing too long; True when it became FORGOTTEN.

    An anchor with an active expectation is not expired: an action has said where it is, and
    only the camera (a retraction) may overrule that.
    """
    if anchor.state not in (AnchorState.MISSING, AnchorState.TENTATIVE):
        return False
    if anchor.missing_since is None or anchor.expectation is not None:
        return False
    limit = config.forget_after if was_confirmed(anchor, config) else config.forget_tentative_after
    if stamp - anchor.missing_since < limit:
        return False
    anchor.state = AnchorState.FORGOTTEN
    return True
