"""Fixtures for the anchoring tests: the shared synthetic scenes, percept makers and cores.

Scenes live in ``anchoring_scenes`` (importable helpers); fixtures hand out fresh, seeded
instances so tests never share random state or anchors.
"""

from __future__ import annotations

from collections.abc import Callable

import pytest

from merlin2_sailor.anchoring import Anchoring, AnchoringConfig, LifecycleConfig

from .anchoring_scenes import KITCHEN, TWIN_MUGS, PerceptMaker, SceneObject


@pytest.fixture
def maker() -> PerceptMaker:
    return PerceptMaker(seed=7)


@pytest.fixture
def kitchen() -> dict[str, SceneObject]:
    return {item.identity: item for item in KITCHEN}


@pytest.fixture
def twin_mugs() -> dict[str, SceneObject]:
    return {item.identity: item for item in TWIN_MUGS}


@pytest.fixture
def quick_lifecycle() -> LifecycleConfig:
    """Confirm after 2 sightings, missing after 1 missed frame, forget after 5 s: short scenarios."""
    return LifecycleConfig(confirm_after=2, missed_frames_to_missing=1, forget_after=5.0, forget_tentative_after=1.0)


@pytest.fixture
def make_anchoring(quick_lifecycle: LifecycleConfig) -> Callable[..., Anchoring]:
    """Build an Anchoring with the quick lifecycle unless a config is given."""

    def build(config: AnchoringConfig | None = None, **options: object) -> Anchoring:
        return Anchoring(config or AnchoringConfig(lifecycle=quick_lifecycle), **options)  # type: ignore[arg-type]

    return build
