"""Fixtures of the world tests: the shipped house, loaded once."""

from __future__ import annotations

import pytest

from merlin2_sailor_demos.world.world_file import WorldDescription, load_world

from .worlds import HOUSE_FILE


@pytest.fixture(scope="session")
def house_description() -> WorldDescription:
    return load_world(HOUSE_FILE)
