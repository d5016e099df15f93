"""Crop embeddings computed once, kept by crop id, persisted as .npz shards.

A crop takes part in many pairs (as a percept, then as an anchor for every later percept of its
scene) and in every epoch; the frozen backbone is by far the costliest step (~20 ms a crop on a
CPU), so each crop goes through it exactly once. :meth:`EmbeddingCache.ensure` embeds the crops
not cached yet, in batches, and writes them as one new shard ``<folder>/<namespace>/shard-N.npz``
(arrays ``ids`` and ``embeddings``); a later run reads the shards back and embeds nothing.

``namespace`` names what the embeddings hold (the embedder's name, e.g.
``efficientnet_lite0+colour42``): features of two makes must never mix. Crop ids of the generated
source embed the source's fingerprint, so a changed generator never reuses stale rows.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from pathlib import Path

import numpy as np

from merlin2_sailor.anchoring.matching_table import Embedder
from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.training.generated_scenes import Observation
from merlin2_sailor.training.progress import progress_bar

#: New rows are persisted in shards of about this many (see :meth:`EmbeddingCache.ensure`).
SHARD_ROWS = 4096


class EmbeddingCache:
    """Embeddings by crop id; ``backbone_crops`` counts the crops this instance sent to the backbone."""

    def __init__(
        self, embedder: Embedder, namespace: str, folder: str | Path | None = None, batch_crops: int = 64
    ) -> None:
        if not namespace or "/" in namespace:
            raise ConfigurationError(f"embedding cache namespace must be a plain name, got {namespace!r}.")
        if batch_crops < 1:
            raise ConfigurationError(f"embedding cache batch_crops must be at least 1, got {batch_crops}.")
        self.embedder = embedder
        self.namespace = namespace
        self.folder = None if folder is None else Path(folder).expanduser() / namespace
        self.batch_crops = batch_crops
        self.backbone_crops = 0
        self._rows: dict[str, int] = {}
        self._blocks: list[np.ndarray] = []
        self._matrix: np.ndarray | None = None
        if self.folder is not None and self.folder.is_dir():
            for shard in sorted(self.folder.glob("shard-*.npz")):
                with np.load(shard, allow_pickle=False) as content:
                    self._add([str(i) for i in content["ids"]], content["embeddings"])

    def __len__(self) -> int:
        return len(self._rows)

    def __contains__(self, crop_id: object) -> bool:
        return crop_id in self._rows

    def ensure(
        self,
        observations: Iterable[Observation],
        render: Callable[[Observation], np.ndarray],
        description: str = "embedding crops",
        total: int | None = None,
    ) -> int:
        """Embed every observation's crop not cached yet; return how many were embedded.

        Streaming: observations are read once, in order, and each batch of ``batch_crops``
        missing crops is rendered and embedded as soon as it is full, so a source that renders
        its crops scene by scene (and keeps only the current scene's) is asked for each crop
        while its scene is at hand. New rows are written as a shard every
        :data:`SHARD_ROWS` rows and at the end, so an interrupted run keeps most of its work.
        """
        ids: list[str] = []
        blocks: list[np.ndarray] = []
        pending: list[Observation] = []
        queued: set[str] = set()
        embedded = 0

        def commit() -> None:
            if ids:
                embeddings = np.concatenate(blocks)
                self._add(ids, embeddings)
                self._persist(ids, embeddings)
                ids.clear()
                blocks.clear()

        with progress_bar(total=total, description=description, unit="crop") as bar:

            def flush() -> None:
                crops = [render(observation) for observation in pending]
                blocks.append(np.asarray(self.embedder.embed(crops), dtype=np.float32))
                self.backbone_crops += len(crops)
                ids.extend(observation.crop_id for observation in pending)
                bar.update(len(pending))
                pending.clear()
                if len(ids) >= SHARD_ROWS:
                    commit()

            for observation in observations:
                if observation.crop_id in self._rows or observation.crop_id in queued:
                    continue
                queued.add(observation.crop_id)
                pending.append(observation)
                embedded += 1
                if len(pending) >= self.batch_crops:
                    flush()
            if pending:
                flush()
        commit()
        return embedded

    def lookup(self, crop_ids: Sequence[str] | np.ndarray) -> np.ndarray:
        """(K, D) float32 embeddings of ``crop_ids``, in order."""
        try:
            rows = np.fromiter((self._rows[i] for i in crop_ids), dtype=np.intp, count=len(crop_ids))
        except KeyError as error:
            raise InvalidInputError(
                f"Crop {error.args[0]} was never embedded; call EmbeddingCache.ensure with its observation first."
            ) from None
        return self._consolidated()[rows]

    def _add(self, ids: list[str], embeddings: np.ndarray) -> None:
        offset = len(self._rows)
        if self._blocks and embeddings.shape[1] != self._blocks[0].shape[1]:
            raise InvalidInputError(
                f"Embeddings of dimension {embeddings.shape[1]} cannot join a cache of dimension "
                f"{self._blocks[0].shape[1]}; use one namespace per backbone."
            )
        for row, crop_id in enumerate(ids):
            self._rows[crop_id] = offset + row
        self._blocks.append(np.asarray(embeddings, dtype=np.float32))
        self._matrix = None

    def _consolidated(self) -> np.ndarray:
        if self._matrix is None:
            self._matrix = np.concatenate(self._blocks) if self._blocks else np.zeros((0, 0), dtype=np.float32)
            self._blocks = [self._matrix]
        return self._matrix

    def _persist(self, ids: list[str], embeddings: np.ndarray) -> None:
        if self.folder is None:
            return
        self.folder.mkdir(parents=True, exist_ok=True)
        number = len(list(self.folder.glob("shard-*.npz")))
        while (self.folder / f"shard-{number:05d}.npz").exists():
            number += 1
        temporary = self.folder / f".shard-{number:05d}.tmp.npz"
        np.savez(temporary, ids=np.array(ids, dtype=str), embeddings=embeddings)
        temporary.rename(self.folder / f"shard-{number:05d}.npz")
