"""Train the matching network on streamed pairs: Adam (lr 0.001, the paper's, then a cosine decay),
binary cross entropy.

Each epoch streams the training scenes' pairs through a shuffle buffer (pairs of one scene are
correlated; the buffer mixes many scenes without holding the data set), looks their crops' features
up in the embedding cache, and takes one Adam step per batch on ``BCEWithLogitsLoss``. After each
epoch every validation pair is scored; the epoch with the best validation F1 (ties: lower loss) is
kept, written with :func:`~merlin2_sailor.anchoring.matching_network.save_network`, whose header
names the backbone, feature encoding and time scale. The data set's hash and the training
history go into a JSON file beside the weights (the weights header has no field for them).
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import torch
from torch import nn

from merlin2_sailor.anchoring.features import FeatureConfig
from merlin2_sailor.anchoring.matching_network import MatchingNetwork, NetworkMetadata, save_network
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.training.embedding_cache import EmbeddingCache
from merlin2_sailor.training.metrics import ConfusionCounts
from merlin2_sailor.training.pair_dataset import PairChunk
from merlin2_sailor.training.progress import progress_bar


@dataclass(frozen=True, slots=True)
class TrainingConfig:
    """``epochs``: passes over the training pairs, the best by validation F1 kept: with 3 (the
    default until 4 December 2026) the validation F1 was still rising at the last epoch (0.922);
    over 10, with the cosine decay stretched over them, the best was epoch 4 (0.934);
    ``device``: "auto" (CUDA when available, else CPU), "cpu" or "cuda";
    ``shuffle_buffer_pairs``: how many pairs are mixed before batches are drawn;
    ``learning_rate``: Adam's (the paper's 0.001) in the first epoch, lowered along a cosine to
    ``final_learning_rate`` in the last: with the paper's constant rate the validation F1 of the
    house source swung by several hundredths from one epoch to the next, so the best epoch was luck;
    ``positive_weight``: how much more a missed true pair costs than a wrong one
    (``BCEWithLogitsLoss``'s ``pos_weight``). Inside the anchoring layer the two mistakes are not
    alike: a wrong pair competes in the one-to-one assignment with the right one, which usually
    scores higher, while a missed one makes a duplicate anchor. Measured on held-out houses, the
    network trained with weight 1 made 23 extra anchors over 162 objects where the rules made
    none; with 8, 2 to 5, at the same pair F1; ``searched_positive_weight``: the same for the
    searched pairs (:mod:`.pair_dataset`), where identity repair compares the scores of rival
    candidates for a lost object, so they stay nearer plain probabilities: with 8 every mug
    of the demo's house scored over 0.9 against the red one, with 1 the red mug itself only 0.62
    against its own anchor seen from afar; with 2, 0.87 against 0.66 for the green mug."""

    epochs: int = 10
    batch_size: int = 256
    learning_rate: float = 0.001
    final_learning_rate: float = 1e-5
    positive_weight: float = 8.0
    searched_positive_weight: float = 2.0
    shuffle_buffer_pairs: int = 65536
    seed: int = 0
    device: str = "auto"
    threshold: float = 0.5

    def __post_init__(self) -> None:
        if self.epochs < 1 or self.batch_size < 1 or self.shuffle_buffer_pairs < 1:
            raise ConfigurationError("training epochs, batch_size and shuffle_buffer_pairs must be at least 1.")
        if not (math.isfinite(self.learning_rate) and self.learning_rate > 0.0):
            raise ConfigurationError(f"training learning_rate must be positive, got {self.learning_rate}.")
        if not (math.isfinite(self.final_learning_rate) and 0.0 < self.final_learning_rate <= self.learning_rate):
            raise ConfigurationError(
                f"training final_learning_rate must be positive and at most learning_rate ({self.learning_rate}), "
                f"got {self.final_learning_rate}."
            )
        if self.device not in ("auto", "cpu", "cuda"):
            raise ConfigurationError(f"training device must be auto, cpu or cuda, got {self.device!r}.")
        if self.device == "cuda" and not torch.cuda.is_available():
            raise ConfigurationError(
                "training device cuda was asked for but torch sees no CUDA device; use auto or cpu."
            )
        for name in ("positive_weight", "searched_positive_weight"):
            if not (math.isfinite(getattr(self, name)) and getattr(self, name) > 0.0):
                raise ConfigurationError(f"training {name} must be positive, got {getattr(self, name)}.")
        if not (0.0 < self.threshold < 1.0):
            raise ConfigurationError(f"training threshold must be in (0, 1), got {self.threshold}.")

    def learning_rate_at(self, epoch: int) -> float:
        """The rate of epoch ``epoch`` (1-based): ``learning_rate`` first, ``final_learning_rate`` last."""
        if self.epochs == 1:
            return self.learning_rate
        progress = (epoch - 1) / (self.epochs - 1)
        return self.final_learning_rate + (self.learning_rate - self.final_learning_rate) * 0.5 * (
            1.0 + math.cos(math.pi * progress))

    def torch_device(self) -> torch.device:
        if self.device == "auto":
            return torch.device("cuda" if torch.cuda.is_available() else "cpu")
        return torch.device(self.device)


@dataclass(frozen=True, slots=True)
class EpochRecord:
    epoch: int
    train_loss: float
    validation_loss: float
    validation: dict[str, float | int]
    seconds: float


@dataclass(slots=True)
class TrainingResult:
    best_epoch: int
    history: list[EpochRecord] = field(default_factory=list)
    seconds: float = 0.0
    device: str = "cpu"

    @property
    def best(self) -> EpochRecord:
        return self.history[self.best_epoch - 1]


class Trainer:
    """Trains one :class:`MatchingNetwork`; ``train_chunks`` / ``validation_chunks`` are called
    once per epoch and return fresh iterators (the pairs are streamed, never stored)."""

    def __init__(
        self,
        metadata: NetworkMetadata,
        cache: EmbeddingCache,
        config: TrainingConfig | None = None,
    ) -> None:
        self.config = config or TrainingConfig()
        self.cache = cache
        self.device = self.config.torch_device()
        torch.manual_seed(self.config.seed)
        self.network = MatchingNetwork(metadata).to(self.device)
        self.optimizer = torch.optim.Adam(self.network.parameters(), lr=self.config.learning_rate)
        self._bce = nn.BCEWithLogitsLoss(reduction="none")
        self._features = FeatureConfig(time_scale=metadata.time_scale)

    def train(
        self,
        train_chunks: Callable[[], Iterable[PairChunk]],
        validation_chunks: Callable[[], Iterable[PairChunk]],
        output: str | Path,
        provenance: dict[str, object] | None = None,
    ) -> TrainingResult:
        """Run every epoch, keep the best weights at ``output`` (+ ``.json`` provenance)."""
        output = Path(output)
        output.parent.mkdir(parents=True, exist_ok=True)
        result = TrainingResult(best_epoch=0, device=str(self.device))
        rng = np.random.default_rng(self.config.seed)
        started = time.perf_counter()
        best_key: tuple[float, float] | None = None
        with progress_bar(self.config.epochs, "epochs", unit="epoch") as epochs_bar:
            for epoch in range(1, self.config.epochs + 1):
                epoch_start = time.perf_counter()
                train_loss = self._train_epoch(train_chunks(), rng, epoch)
                validation_loss, counts = self.validate(validation_chunks())
                record = EpochRecord(epoch, train_loss, validation_loss, counts.as_dict(),
                                     time.perf_counter() - epoch_start)
                result.history.append(record)
                key = (-_finite(counts.f1), validation_loss)
                if best_key is None or key < best_key:
                    best_key, result.best_epoch = key, epoch
                    save_network(self.network, output)
                epochs_bar.update(1)
                epochs_bar.set_postfix(train_loss=f"{train_loss:.4f}", val_f1=f"{counts.f1:.4f}")
        result.seconds = time.perf_counter() - started
        write_provenance(output, result, self.config, provenance or {})
        return result

    def _train_epoch(self, chunks: Iterable[PairChunk], rng: np.random.Generator, epoch: int) -> float:
        self.network.train()
        for group in self.optimizer.param_groups:
            group["lr"] = self.config.learning_rate_at(epoch)
        total, count = 0.0, 0
        with progress_bar(None, f"epoch {epoch}", unit="pair") as bar:
            for batch in shuffled_batches(chunks, self.config.batch_size, self.config.shuffle_buffer_pairs, rng):
                inputs, labels = self._tensors(batch)
                self.optimizer.zero_grad(set_to_none=True)
                loss = self.loss(self.network(*inputs), labels, batch)
                loss.backward()
                self.optimizer.step()
                total += float(loss.detach()) * len(batch)
                count += len(batch)
                bar.update(len(batch))
        if not count:
            raise ConfigurationError("The training split produced no pairs; generate more scenes or samples per scene.")
        return total / count

    @torch.no_grad()
    def validate(self, chunks: Iterable[PairChunk]) -> tuple[float, ConfusionCounts]:
        """Mean loss and confusion counts of the current network over every validation pair."""
        self.network.eval()
        total, count = 0.0, 0
        counts = ConfusionCounts()
        for chunk in chunks:
            for start in range(0, len(chunk), 4 * self.config.batch_size):
                batch = chunk.take(slice(start, start + 4 * self.config.batch_size))
                inputs, labels = self._tensors(batch)
                logits = self.network(*inputs)
                total += float(self.loss(logits, labels, batch)) * len(batch)
                count += len(batch)
                scores = torch.sigmoid(logits).cpu().numpy()
                counts += ConfusionCounts.from_scores(batch.labels, scores, self.config.threshold)
        if not count:
            raise ConfigurationError("The validation split produced no pairs; generate more validation scenes.")
        return total / count, counts

    def loss(self, logits: torch.Tensor, labels: torch.Tensor, batch: PairChunk) -> torch.Tensor:
        """Mean binary cross entropy, a true pair weighing ``positive_weight`` times a false one
        (``searched_positive_weight`` times in a searched pair; see :class:`TrainingConfig`)."""
        weights = torch.ones_like(labels)
        true_pairs = torch.from_numpy(batch.labels).to(self.device)
        searched = torch.from_numpy(batch.searched).to(self.device)
        weights[true_pairs & ~searched] = self.config.positive_weight
        weights[true_pairs & searched] = self.config.searched_positive_weight
        return (self._bce(logits, labels) * weights).mean()

    def _tensors(self, batch: PairChunk) -> tuple[tuple[torch.Tensor, ...], torch.Tensor]:
        features = batch.features(self._features, batch.embeddings(self.cache.lookup))
        inputs = tuple(tensor.to(self.device, non_blocking=True) for tensor in self.network.inputs_from(features))
        labels = torch.from_numpy(batch.labels.astype(np.float32)).to(self.device)
        return inputs, labels


def shuffled_batches(
    chunks: Iterable[PairChunk], batch_size: int, buffer_pairs: int, rng: np.random.Generator
) -> Iterator[PairChunk]:
    """Batches drawn from a shuffle buffer of up to ``buffer_pairs`` pairs filled from ``chunks``."""
    buffer: list[PairChunk] = []
    buffered = 0

    def drain(final: bool) -> Iterator[PairChunk]:
        nonlocal buffer, buffered
        merged = PairChunk.concatenate(buffer).take(rng.permutation(buffered))
        keep = 0 if final else buffered // 2  # keep half, so consecutive fills mix
        usable = buffered - keep
        for start in range(0, usable - (0 if final else usable % batch_size), batch_size):
            yield merged.take(slice(start, min(start + batch_size, usable)))
        if not final:
            consumed = usable - usable % batch_size
            rest = merged.take(slice(consumed, None))
            buffer, buffered = [rest], len(rest)

    for chunk in chunks:
        buffer.append(chunk)
        buffered += len(chunk)
        if buffered >= buffer_pairs:
            yield from drain(final=False)
    if buffered:
        yield from drain(final=True)


def write_provenance(output: Path, result: TrainingResult, config: TrainingConfig, extra: dict[str, object]) -> Path:
    """``<weights>.json``: what the weights were trained on and how they did, for people and tests."""
    path = output.with_suffix(".json")
    content = {
        **extra,
        "training": asdict(config),
        "device": result.device,
        "best_epoch": result.best_epoch,
        "training_seconds": round(result.seconds, 1),
        "history": [asdict(record) for record in result.history],
    }
    path.write_text(json.dumps(_clean(content), indent=2, allow_nan=False) + "\n")
    return path


def _finite(value: float) -> float:
    return value if math.isfinite(value) else 0.0


def _clean(value: object) -> object:
    """JSON-safe: NaN and infinities become null, NumPy scalars plain numbers, tuples lists."""
    if isinstance(value, dict):
        return {str(key): _clean(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_clean(item) for item in value]
    if isinstance(value, float | np.floating):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    if value is None or isinstance(value, bool | int | str):
        return value
    return str(value)
