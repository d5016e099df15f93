"""The grounding configuration the package ships loads and grounds a real-looking anchor."""

from __future__ import annotations

from merlin2_sailor.knowledge import Grounding, GroundingConfig
from merlin2_sailor.resources import config_file


def test_shipped_grounding_places_a_cup_at_the_kitchen_waypoint(make_anchor) -> None:
    grounding = Grounding(GroundingConfig.from_yaml(config_file("grounding.yaml")))
    cup = make_anchor("cup_1", "cup", 4.3, 1.2)
    grounded = grounding.ground([cup])["cup_1"]
    assert grounded.object.type == "cup"
    facts = {(fact.predicate, fact.objects) for fact in grounded.facts}
    assert ("object_at", ("cup_1", "kitchen")) in facts
    assert ("seen", ("cup_1",)) in facts
