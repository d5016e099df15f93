"""Fixtures of the identity tests: small generated houses (two rooms, a few objects) that tour fast."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from merlin2_sailor.training.photo_library import DARKNET_ENVIRONMENT_VARIABLE, DEFAULT_DARKNET_FOLDER
from merlin2_sailor_demos.identity.generated_houses import HouseGeneratorConfig

#: Two rooms side by side, a few objects each: a tour takes about a second to render at 3 Hz.
SMALL_HOUSES = HouseGeneratorConfig(columns=(2, 2), rows=(1, 1), objects_per_room=(3, 4), furniture_per_room=(1, 2),
                                    use_darknet=False)

REPOSITORY_ROOT = Path(__file__).resolve().parents[4]
DEMO_HOUSE = REPOSITORY_ROOT / "config" / "worlds" / "house.yaml"


def darknet_installed() -> bool:
    folder = Path(os.environ.get(DARKNET_ENVIRONMENT_VARIABLE) or DEFAULT_DARKNET_FOLDER)
    return (folder / "dog.jpg").is_file()


@pytest.fixture
def small_houses() -> HouseGeneratorConfig:
    return SMALL_HOUSES
