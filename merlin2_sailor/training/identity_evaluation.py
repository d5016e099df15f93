"""Anchoring-level identity metrics: run the whole anchoring layer over generated sequences.

Pair metrics say how well M scores pairs in isolation; what a robot feels is whether each
physical object keeps one symbol. Every scene is replayed through a fresh
:class:`~merlin2_sailor.anchoring.anchoring.Anchoring` (gating, Hungarian assignment, fusion,
galleries: everything) and the symbol given to each percept is compared with the percept's
ground-truth instance by motmetrics, as a multi-object tracker would be: each percept is both a
ground-truth object and a hypothesis, so the scores measure identity only (ID switches, IDF1),
never detection. Percepts carry their crop's cached embedding, so no crop is embedded twice.

No camera view is passed (there is no depth image): anchors are never marked missing, which
leaves the identity decisions, the subject here, unchanged.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass

import numpy as np

from merlin2_sailor.anchoring.anchoring import Anchoring, AnchoringConfig
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.contract.percept import BoundingBox2D, Percept
from merlin2_sailor.errors import DependencyError
from merlin2_sailor.training.embedding_cache import EmbeddingCache
from merlin2_sailor.training.generated_scenes import Scene


@dataclass(frozen=True, slots=True)
class IdentityMetrics:
    """Over all scenes: ``instances`` (ground-truth objects), ``anchors`` (symbols created; equal
    to ``instances`` when nothing was split), ``id_switches``, ``idf1`` / ``idp`` / ``idr``, ``mota``,
    and ``unresolved``: percepts left without a symbol (views too far to tell)."""

    scenes: int
    percepts: int
    instances: int
    anchors: int
    id_switches: int
    idf1: float
    idp: float
    idr: float
    mota: float
    unresolved: int = 0

    def as_dict(self) -> dict[str, float | int]:
        return asdict(self)


def motmetrics_module():  # type: ignore[no-untyped-def]
    """Import motmetrics; 1.4 calls ``np.asfarray``, gone in NumPy 2, so it is provided if missing."""
    if not hasattr(np, "asfarray"):
        np.asfarray = lambda values, dtype=np.float64: np.asarray(values, dtype=dtype)  # type: ignore[attr-defined]
    try:
        import motmetrics
    except ImportError as error:
        raise DependencyError(f"Anchoring-level metrics need motmetrics (`pip install motmetrics`): {error}") from error
    return motmetrics


def evaluate_identities(
    matcher_factory: Callable[[], Matcher],
    scenes: Iterable[Scene],
    cache: EmbeddingCache | None = None,
    config: AnchoringConfig | None = None,
) -> IdentityMetrics:
    """Replay ``scenes`` through a fresh Anchoring each (matcher from ``matcher_factory``)."""
    motmetrics = motmetrics_module()
    accumulators, names = [], []
    percept_count = instances = anchors = unresolved = 0
    for scene in scenes:
        matcher = matcher_factory()
        anchoring = Anchoring(config, matcher)
        accumulator = motmetrics.MOTAccumulator(auto_id=True)
        symbol_numbers: dict[str, int] = {}  # motmetrics wants numeric hypothesis ids
        instances_seen: set[int] = set()
        for sample in scene.samples:
            observations = sample.observations
            embeddings = None
            if matcher.uses_appearance and observations:
                if cache is None:
                    raise DependencyError("An appearance matcher needs the embedding cache of the scenes' crops.")
                embeddings = cache.lookup([o.crop_id for o in observations])
            percepts = [
                Percept(
                    class_name=o.class_name,
                    score=0.9,
                    box=BoundingBox2D(0.0, 0.0, float(o.view.pixels[0]), float(o.view.pixels[1])),
                    position=o.position,
                    size=o.size,
                    stamp=sample.stamp,
                    embedding=None if embeddings is None else embeddings[row],
                )
                for row, o in enumerate(observations)
            ]
            # The renderer knows which views are cut by the image's edge or an occluder, as the node
            # tells from its camera: those are scored without their look, here as on the robot.
            result = anchoring.process(percepts, None, sample.stamp, [o.partial for o in observations])
            truth = [o.instance for o in observations]
            # A percept left unresolved (a view too far to tell, merlin2_sailor.anchoring.far_view) names no anchor:
            # its object counts as missed in that frame, never as a symbol.
            named = [row for row, symbol in enumerate(result.percept_symbols) if symbol]
            hypotheses = [symbol_numbers.setdefault(result.percept_symbols[row], len(symbol_numbers)) for row in named]
            distances = np.full((len(truth), len(hypotheses)), np.nan)
            distances[named, np.arange(len(named))] = 0.0
            unresolved += len(truth) - len(named)
            accumulator.update(truth, hypotheses, distances)
            instances_seen.update(truth)
            percept_count += len(observations)
        accumulators.append(accumulator)
        names.append(scene.scene_id)
        instances += len(instances_seen)
        anchors += len(symbol_numbers)
    if not accumulators:
        raise DependencyError("No scenes to evaluate identities on.")
    summary = motmetrics.metrics.create().compute_many(
        accumulators, metrics=["num_switches", "idf1", "idp", "idr", "mota"], names=names, generate_overall=True
    )
    overall = summary.loc["OVERALL"]
    return IdentityMetrics(
        scenes=len(accumulators),
        percepts=percept_count,
        instances=instances,
        anchors=anchors,
        id_switches=int(overall["num_switches"]),
        idf1=float(overall["idf1"]),
        idp=float(overall["idp"]),
        idr=float(overall["idr"]),
        mota=float(overall["mota"]),
        unresolved=unresolved,
    )


def format_identity_table(rows: dict[str, IdentityMetrics]) -> str:
    width = max([len(name) for name in rows] + [8])
    lines = [
        f"{'':<{width}}  {'percepts':>8} {'objects':>8} {'anchors':>8} {'ID sw.':>7} "
        f"{'IDF1':>7} {'IDP':>7} {'IDR':>7} {'MOTA':>7} {'unresolved':>10}"
    ]
    for name, m in rows.items():
        lines.append(
            f"{name:<{width}}  {m.percepts:>8d} {m.instances:>8d} {m.anchors:>8d} {m.id_switches:>7d} "
            f"{m.idf1:>7.4f} {m.idp:>7.4f} {m.idr:>7.4f} {m.mota:>7.4f} {m.unresolved:>10d}"
        )
    return "\n".join(lines)
