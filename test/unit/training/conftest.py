"""Shared fixtures of the training tests: a cheap stand-in embedder and hand-made scenes."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pytest

from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.training.crop_renderer import Region, ViewChange
from merlin2_sailor.training.generated_scenes import Observation, Sample, Scene


class ColourEmbedder:
    """Counts the crops it embeds; features are colour statistics (mean and spread per channel
    on a 2 x 2 grid: 24 numbers), enough appearance signal for a network to learn from."""

    def __init__(self) -> None:
        self.crops = 0
        self.calls = 0

    def embed(self, crops: Sequence[np.ndarray]) -> np.ndarray:
        self.calls += 1
        self.crops += len(crops)
        rows = []
        for crop in crops:
            crop = np.asarray(crop, dtype=np.float32) / 255.0
            height, width = crop.shape[:2]
            cells = [crop[: height // 2 or 1, : width // 2 or 1], crop[: height // 2 or 1, width // 2 :],
                     crop[height // 2 :, : width // 2 or 1], crop[height // 2 :, width // 2 :]]
            rows.append(np.concatenate([np.r_[c.reshape(-1, 3).mean(0), c.reshape(-1, 3).std(0)] for c in cells]))
        return np.asarray(rows, dtype=np.float32).reshape(len(crops), 24)


@pytest.fixture
def colour_embedder() -> ColourEmbedder:
    return ColourEmbedder()


def observation(
    instance: int, sample: int, class_name: str = "cup", position=(0.0, 0.0, 0.0), stamp=None, twin: bool = False,
    **known,
) -> Observation:
    """A hand-made observation (region and view are placeholders: never rendered); ``known``: the
    keyword-only fields a source that knows more fills (partial, anchor_position, ...)."""
    return Observation(
        crop_id=f"hand/{sample}/{instance}",
        instance=instance,
        class_name=class_name,
        sample=sample,
        stamp=float(sample if stamp is None else stamp),
        position=np.asarray(position, dtype=np.float64),
        size=np.full(3, 0.2),
        depth=2.0,
        twin=twin,
        region=Region(0, 0.0, 0.0, 10.0, 10.0),
        view=ViewChange(tuple([0.0] * 8), 0.0, 1.0, 0.0, 0.0, 0.0, 0, (16, 16)),
        **known,
    )


def hand_scene(samples: list[list[Observation]], scene_id: str = "hand/0") -> Scene:
    return Scene(
        scene_id=scene_id,
        split="hand",
        index=0,
        samples=tuple(Sample(float(i), Pose.identity(), tuple(obs)) for i, obs in enumerate(samples)),
    )
