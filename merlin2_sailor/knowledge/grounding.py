"""The grounding relation G: which PDDL object and facts an anchor stands for.

G is configuration, not code, so a deployment changes its types, map and predicate names in
YAML. It is defined against :class:`GroundableAnchor`, a structural protocol, because the Anchor
dataclass belongs to the anchoring layer; anything with those attributes can be grounded. Every
anchor of a frame is located in one vectorised pass, so grounding a thousand anchors costs about
as much as grounding one.
"""

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from types import MappingProxyType
from typing import Any, Protocol

import numpy as np
import yaml

from merlin2_sailor.errors import ConfigurationError, InvalidInputError, SailorError
from merlin2_sailor.knowledge.model import (
    ROOT_TYPE,
    KnowledgeItem,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
    Provenance,
)
from merlin2_sailor.knowledge.naming import to_identifier


class GroundableAnchor(Protocol):
    """What grounding reads from an anchor; positions are in the fixed world frame."""

    @property
    def symbol(self) -> str: ...

    @property
    def class_name(self) -> str: ...

    @property
    def position(self) -> np.ndarray: ...

    @property
    def state(self) -> str | Enum: ...

    @property
    def visible(self) -> bool: ...


class SizedAnchor(GroundableAnchor, Protocol):
    """An anchor that also knows its 3D size, needed only when size categories are set."""

    @property
    def size(self) -> np.ndarray: ...


@dataclass(frozen=True)
class Waypoint:
    """A named point of the map, as MERLIN2's navigation uses them."""

    name: str
    x: float
    y: float
    yaw: float | None = None
    """Heading (radians, world frame) a robot should face on arrival; None when any will do."""


@dataclass(frozen=True)
class Region:
    """A named axis-aligned rectangle of the map, e.g. a room."""

    name: str
    x_min: float
    y_min: float
    x_max: float
    y_max: float

    def __post_init__(self) -> None:
        if not (self.x_min < self.x_max and self.y_min < self.y_max):
            raise ConfigurationError(
                f"region {self.name!r} needs x_min < x_max and y_min < y_max, got "
                f"x {self.x_min}..{self.x_max}, y {self.y_min}..{self.y_max}"
            )

    @property
    def area(self) -> float:
        return (self.x_max - self.x_min) * (self.y_max - self.y_min)


@dataclass(frozen=True)
class SizeCategory:
    """A unary predicate (``small``) for objects whose largest side is at most ``max_extent`` m."""

    name: str
    max_extent: float


@dataclass(frozen=True)
class GroundingConfig:
    """The data that defines G; build it from YAML with :meth:`from_mapping` or :meth:`from_yaml`.

    Names in the configuration go through :func:`~merlin2_sailor.knowledge.naming.to_identifier`,
    so "Dining Table" in YAML and "dining table" from a detector meet as ``dining_table``.
    """

    class_types: Mapping[str, str] = field(default_factory=dict)
    """Detector class name -> PDDL type; classes not listed get :attr:`fallback_type`."""
    fallback_type: str = ROOT_TYPE
    supertypes: Mapping[str, str] = field(default_factory=dict)
    """Type -> its supertype, for hierarchies such as cup -> container."""
    location_type: str = "wp"
    """Type of waypoints and regions; MERLIN2's navigation calls its waypoints ``wp``."""
    waypoints: tuple[Waypoint, ...] = ()
    regions: tuple[Region, ...] = ()
    max_waypoint_distance: float = 1.0
    """Metres; farther than this from every waypoint, an object is placed by region or nowhere."""
    at_predicate: str = "object_at"
    seen_predicate: str = "seen"
    visible_predicate: str = "visible"
    missing_predicate: str = "missing"
    """Written for an anchor in state MISSING, which then has no ``at`` fact: the camera saw its
    place without it, so the planner must not rely on the old location, and a search action can
    take ``missing(?o)`` as its condition."""
    ungrounded_states: frozenset[str] = frozenset({"tentative", "forgotten"})
    """Anchor states that have no symbol in the knowledge base (yet, or any more)."""
    size_categories: tuple[SizeCategory, ...] = ()

    def __post_init__(self) -> None:
        try:
            self._normalise()
        except SailorError as error:
            raise ConfigurationError(f"invalid grounding configuration: {error}") from error

    def _normalise(self) -> None:
        def name(text: str) -> str:
            return to_identifier(str(text))

        def setting(attribute: str, value: Any) -> None:
            object.__setattr__(self, attribute, value)

        setting(
            "class_types",
            MappingProxyType({name(k): name(v) for k, v in self.class_types.items()}),
        )
        setting(
            "supertypes", MappingProxyType({name(k): name(v) for k, v in self.supertypes.items()})
        )
        for attribute in (
            "fallback_type",
            "location_type",
            "at_predicate",
            "seen_predicate",
            "visible_predicate",
            "missing_predicate",
        ):
            setting(attribute, name(getattr(self, attribute)))
        setting("ungrounded_states", frozenset(str(s).lower() for s in self.ungrounded_states))
        setting(
            "waypoints",
            tuple(
                Waypoint(name(w.name), float(w.x), float(w.y), None if w.yaw is None else float(w.yaw))
                for w in self.waypoints
            ),
        )
        setting(
            "regions",
            tuple(Region(name(r.name), r.x_min, r.y_min, r.x_max, r.y_max) for r in self.regions),
        )
        setting(
            "size_categories",
            tuple(
                sorted(
                    (SizeCategory(name(c.name), float(c.max_extent)) for c in self.size_categories),
                    key=lambda category: category.max_extent,
                )
            ),
        )
        if not (self.max_waypoint_distance > 0 and math.isfinite(self.max_waypoint_distance)):
            raise ConfigurationError(
                f"max_waypoint_distance must be a positive number of metres, "
                f"got {self.max_waypoint_distance!r}"
            )
        locations = [waypoint.name for waypoint in self.waypoints]
        locations += [region.name for region in self.regions]
        repeated = sorted({place for place in locations if locations.count(place) > 1})
        if repeated:
            raise ConfigurationError(f"waypoints and regions must have distinct names: {repeated}")

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any]) -> "GroundingConfig":
        """Read the YAML layout, for example::

        class_types: {cup: cup, "wine glass": glass}
        fallback_type: object
        supertypes: {cup: container, glass: container}
        location_type: wp
        map:
          waypoints: [{name: kitchen, x: 1.0, y: 2.0, yaw: 1.57}]  # or {kitchen: [1.0, 2.0]}; yaw optional
          regions: [{name: living_room, x_min: 0, y_min: 0, x_max: 5, y_max: 4}]
        max_waypoint_distance: 1.0
        predicates: {at: object_at, seen: seen, visible: visible, missing: missing}
        ungrounded_states: [tentative, forgotten]
        size_categories: {small: 0.3, medium: 1.0}
        """
        known = {
            "class_types", "fallback_type", "supertypes", "location_type", "map",
            "max_waypoint_distance", "predicates", "ungrounded_states", "size_categories",
        }  # fmt: skip
        unknown = sorted(set(data) - known)
        if unknown:
            raise ConfigurationError(
                f"unknown grounding setting(s) {unknown}; known ones are {sorted(known)}"
            )
        try:
            map_data = data.get("map") or {}
            predicates = data.get("predicates") or {}
            options: dict[str, Any] = {
                key: data[key]
                for key in ("class_types", "fallback_type", "supertypes", "location_type")
                if key in data
            }
            if "max_waypoint_distance" in data:
                options["max_waypoint_distance"] = float(data["max_waypoint_distance"])
            if "ungrounded_states" in data:
                options["ungrounded_states"] = frozenset(data["ungrounded_states"])
            for role in ("at", "seen", "visible", "missing"):
                if role in predicates:
                    options[f"{role}_predicate"] = predicates[role]
            options["waypoints"] = _waypoints(map_data.get("waypoints") or [])
            options["regions"] = tuple(
                Region(
                    r["name"],
                    float(r["x_min"]),
                    float(r["y_min"]),
                    float(r["x_max"]),
                    float(r["y_max"]),
                )
                for r in map_data.get("regions") or []
            )
            options["size_categories"] = tuple(
                SizeCategory(category, float(extent))
                for category, extent in (data.get("size_categories") or {}).items()
            )
        except (KeyError, TypeError, ValueError, AttributeError) as error:
            raise ConfigurationError(
                f"malformed grounding configuration ({error!r}); compare it with the "
                "example in GroundingConfig.from_mapping"
            ) from error
        return cls(**options)

    @classmethod
    def from_yaml(cls, path: str | Path) -> "GroundingConfig":
        """Load a grounding configuration file."""
        try:
            data = yaml.safe_load(Path(path).read_text(encoding="utf-8")) or {}
        except (OSError, yaml.YAMLError) as error:
            raise ConfigurationError(
                f"cannot read grounding file {str(path)!r}: {error}"
            ) from error
        if not isinstance(data, Mapping):
            raise ConfigurationError(f"grounding file {str(path)!r} must hold a mapping")
        return cls.from_mapping(data)


def _waypoints(data: Any) -> tuple[Waypoint, ...]:
    """``{kitchen: [x, y]}`` or ``{kitchen: [x, y, yaw]}``, or a list of ``{name, x, y[, yaw]}``."""
    if isinstance(data, Mapping):
        return tuple(
            Waypoint(name, float(values[0]), float(values[1]), _optional_float(values[2:3]))
            for name, values in data.items()
        )
    return tuple(
        Waypoint(w["name"], float(w["x"]), float(w["y"]), _optional_float([w["yaw"]] if "yaw" in w else []))
        for w in data
    )


def _optional_float(values: Any) -> float | None:
    return float(values[0]) if len(values) and values[0] is not None else None


@dataclass(frozen=True)
class GroundedAnchor:
    """An anchor as the knowledge base sees it: one object and its perceived facts.

    ``visible`` says whether the facts are fresh evidence or the last known state of an anchor
    out of view, which decides what they may overrule. An anchor in view is fresh evidence, and
    so is a missing one: the camera has just seen its place without it.
    """

    object: PddlObject
    facts: frozenset[Proposition]
    visible: bool


class Grounding:
    """Applies G to anchors; holds nothing but its configuration and a name cache."""

    def __init__(self, config: GroundingConfig | None = None) -> None:
        self.config = config if config is not None else GroundingConfig()
        self._locations: tuple[Waypoint | Region, ...] = (
            *self.config.waypoints,
            *self.config.regions,
        )
        self._waypoint_names = [waypoint.name for waypoint in self.config.waypoints]
        self._waypoint_xy = np.array(
            [[waypoint.x, waypoint.y] for waypoint in self.config.waypoints], dtype=float
        ).reshape(-1, 2)
        # Smallest region first, so an object in a table area inside a room is put on the table.
        self._regions = sorted(self.config.regions, key=lambda region: region.area)
        self._region_bounds = np.array(
            [[r.x_min, r.y_min, r.x_max, r.y_max] for r in self._regions], dtype=float
        ).reshape(-1, 4)
        self._type_of_class: dict[str, str] = {}

    @property
    def managed_predicates(self) -> frozenset[str]:
        """The predicates whose facts about an anchored object perception is the authority on."""
        config = self.config
        return frozenset(
            {
                config.at_predicate,
                config.seen_predicate,
                config.visible_predicate,
                config.missing_predicate,
                *(category.name for category in config.size_categories),
            }
        )

    def declarations(self) -> tuple[KnowledgeItem, ...]:
        """The types, predicates and location objects the facts need, in dependency order."""
        config = self.config
        type_names = {config.location_type, config.fallback_type, *config.class_types.values()}
        type_names |= set(config.supertypes) | set(config.supertypes.values())
        types = [
            PddlType(type_name, config.supertypes.get(type_name, ROOT_TYPE))
            for type_name in sorted(type_names - {ROOT_TYPE})
        ]
        predicates = [
            Predicate(config.at_predicate, (ROOT_TYPE, config.location_type)),
            Predicate(config.seen_predicate, (ROOT_TYPE,)),
            Predicate(config.visible_predicate, (ROOT_TYPE,)),
            Predicate(config.missing_predicate, (ROOT_TYPE,)),
            *(Predicate(category.name, (ROOT_TYPE,)) for category in config.size_categories),
        ]
        locations = [PddlObject(place.name, config.location_type) for place in self._locations]
        return (*types, *predicates, *locations)

    def type_of(self, class_name: str) -> str:
        """The PDDL type of a detector class."""
        type_name = self._type_of_class.get(class_name)
        if type_name is None:
            type_name = self.config.class_types.get(
                to_identifier(class_name, fallback=self.config.fallback_type),
                self.config.fallback_type,
            )
            self._type_of_class[class_name] = type_name
        return type_name

    def ground(self, anchors: Iterable[GroundableAnchor]) -> dict[str, GroundedAnchor]:
        """Ground every anchor whose state has a symbol, keyed by symbol.

        Raises:
            InvalidInputError: two anchors share a symbol.
        """
        config = self.config
        grounded_anchors = [
            anchor
            for anchor in anchors
            if _state_name(anchor.state) not in config.ungrounded_states
        ]
        locations = self._locate(grounded_anchors)
        result: dict[str, GroundedAnchor] = {}
        for anchor, location in zip(grounded_anchors, locations, strict=True):
            if anchor.symbol in result:
                raise InvalidInputError(
                    f"two anchors share the symbol {anchor.symbol!r}; symbols must be unique, "
                    "take them from one persistent counter (the anchoring node's SymbolCounter)"
                )
            name = anchor.symbol
            facts = [Proposition(config.seen_predicate, (name,), provenance=Provenance.PERCEIVED)]
            if anchor.visible:
                facts.append(
                    Proposition(config.visible_predicate, (name,), provenance=Provenance.PERCEIVED)
                )
            missing = _state_name(anchor.state) == "missing"
            if missing:
                facts.append(
                    Proposition(config.missing_predicate, (name,), provenance=Provenance.PERCEIVED)
                )
            elif location is not None:
                facts.append(
                    Proposition(
                        config.at_predicate, (name, location), provenance=Provenance.PERCEIVED
                    )
                )
            category = self._size_category(anchor)
            if category is not None:
                facts.append(Proposition(category, (name,), provenance=Provenance.PERCEIVED))
            result[name] = GroundedAnchor(
                PddlObject(name, self.type_of(anchor.class_name)),
                frozenset(facts),
                bool(anchor.visible) or missing,
            )
        return result

    def _locate(self, anchors: list[GroundableAnchor]) -> list[str | None]:
        """The nearest waypoint within range, else the smallest containing region, else None."""
        if not anchors or not self._locations:
            return [None] * len(anchors)
        xy = np.array([np.asarray(anchor.position, dtype=float)[:2] for anchor in anchors])
        locations: list[str | None] = [None] * len(anchors)
        if len(self._waypoint_names):
            distances = np.linalg.norm(xy[:, None, :] - self._waypoint_xy[None, :, :], axis=2)
            distances[~np.isfinite(distances)] = np.inf
            nearest = distances.argmin(axis=1)
            in_range = (
                distances[np.arange(len(anchors)), nearest] <= self.config.max_waypoint_distance
            )
            for row in np.flatnonzero(in_range):
                locations[row] = self._waypoint_names[nearest[row]]
        if self._regions:
            x, y = xy[:, 0:1], xy[:, 1:2]
            bounds = self._region_bounds
            inside = (
                (x >= bounds[:, 0])
                & (y >= bounds[:, 1])
                & (x <= bounds[:, 2])
                & (y <= bounds[:, 3])
            )
            first_inside = inside.argmax(axis=1)
            for row in np.flatnonzero(inside.any(axis=1)):
                if locations[row] is None:
                    locations[row] = self._regions[first_inside[row]].name
        return locations

    def _size_category(self, anchor: GroundableAnchor) -> str | None:
        categories = self.config.size_categories
        if not categories:
            return None
        size = getattr(anchor, "size", None)
        if size is None:
            return None
        largest = float(np.max(np.asarray(size, dtype=float)))
        for category in categories:
            if largest <= category.max_extent:
                return category.name
        return None


def _state_name(state: str | Enum) -> str:
    return state.name.lower() if isinstance(state, Enum) else str(state).lower()
