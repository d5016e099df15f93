"""The generated source's splits as pair sets: scenes -> observations -> pairs, all streamed.

Splits are disjoint by construction (scenes of a split are seeded by the split's name), so a
network trained on ``train`` and chosen on ``validation`` is tested on ``test`` scenes it has never
seen. One object ties a split to the pair builder and the embedding cache, so the training and
evaluation commands and the tests read data the same way.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.training.embedding_cache import EmbeddingCache
from merlin2_sailor.training.generated_scenes import GeneratedSource, Observation, Scene
from merlin2_sailor.training.pair_dataset import PairChunk, PairDatasetConfig, iter_pair_chunks

#: The split names the commands use.
TRAIN, VALIDATION, TEST = "train", "validation", "test"


@dataclass(frozen=True, slots=True)
class SplitSizes:
    """Scenes per split. The defaults keep the default training within a few CPU minutes."""

    train: int = 40
    validation: int = 6
    test: int = 8

    def __post_init__(self) -> None:
        for name in ("train", "validation", "test"):
            if getattr(self, name) < 0:
                raise ConfigurationError(f"split size {name} must be >= 0, got {getattr(self, name)}.")

    def as_dict(self) -> dict[str, int]:
        return {TRAIN: self.train, VALIDATION: self.validation, TEST: self.test}


@dataclass(frozen=True, slots=True, eq=False)
class GeneratedPairSet:
    """The pairs of ``count`` scenes of one split (from scene ``first``)."""

    source: GeneratedSource
    split: str
    count: int
    pairs: PairDatasetConfig
    first: int = 0

    def scenes(self) -> Iterator[Scene]:
        return self.source.scenes(self.split, self.count, self.first)

    def observations(self) -> Iterator[Observation]:
        for scene in self.scenes():
            yield from scene.observations

    def chunks(self) -> Iterator[PairChunk]:
        return iter_pair_chunks(self.scenes(), self.pairs)

    def embed(self, cache: EmbeddingCache) -> int:
        """Make sure every crop of the split is in ``cache``; return how many were embedded now."""
        return cache.ensure(self.observations(), self.source.render, description=f"embedding {self.split} crops")


def default_cache_folder() -> Path:
    """``$SAILOR_CACHE`` or ``$XDG_CACHE_HOME/merlin2_sailor`` (``~/.cache/merlin2_sailor``) + ``/embeddings``."""
    root = os.environ.get("SAILOR_CACHE") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "merlin2_sailor"
    )
    return Path(root) / "embeddings"
