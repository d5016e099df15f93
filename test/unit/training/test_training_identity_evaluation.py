"""The anchoring-level replay (:mod:`merlin2_sailor.training.identity_evaluation`): a percept the
anchoring layer leaves unresolved (a view too far to tell) counts as unresolved, never as a symbol."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("motmetrics", reason="pip install motmetrics (the anchoring-level metrics)")

from merlin2_sailor.anchoring.anchoring import AnchoringConfig  # noqa: E402
from merlin2_sailor.anchoring.far_view import FarViewConfig  # noqa: E402
from merlin2_sailor.anchoring.features import FeatureConfig, PairFeatures  # noqa: E402
from merlin2_sailor.anchoring.matcher import Matcher  # noqa: E402
from merlin2_sailor.contract.pose import Pose  # noqa: E402
from merlin2_sailor.training.crop_renderer import Region, ViewChange  # noqa: E402
from merlin2_sailor.training.generated_scenes import Observation, Sample, Scene  # noqa: E402
from merlin2_sailor.training.identity_evaluation import evaluate_identities, format_identity_table  # noqa: E402

SHARP, BLURRED = np.eye(4, dtype=np.float32)[0], np.array([0.6, 0.8, 0.0, 0.0], dtype=np.float32)


class LookOnly(Matcher):
    """Sure of its own look (1.0), unsure of any other (0.3): between the far-view floor and the threshold."""

    uses_appearance = True

    @property
    def feature_config(self) -> FeatureConfig:
        return FeatureConfig()

    def score_pairs(self, features: PairFeatures) -> np.ndarray:
        return np.where(features.appearance_distance < 0.1, 1.0, 0.3)


class Embeddings:
    """An embedding cache by crop id, as :class:`~merlin2_sailor.training.embedding_cache.EmbeddingCache` looks."""

    def __init__(self, rows: dict[str, np.ndarray]) -> None:
        self.rows = rows

    def lookup(self, crop_ids) -> np.ndarray:
        return np.stack([self.rows[crop_id] for crop_id in crop_ids])


def observation(number: int, side: int) -> Observation:
    view = ViewChange(corners=(0.0,) * 8, rotation_degrees=0.0, gain=1.0, bias=0.0, blur_sigma=0.0, noise_sigma=0.0,
                      noise_seed=0, pixels=(side, side))
    return Observation(crop_id=f"mug/{number}", instance=0, class_name="cup", sample=number, stamp=float(number) * 20.0,
                       position=np.array([2.0, 0.0, 0.8]), size=np.array([0.1, 0.1, 0.12]), depth=2.0, twin=False,
                       region=Region(-1, 0.0, 0.0, side, side), view=view)


def test_a_far_view_left_unresolved_is_counted_as_such_and_makes_no_anchor() -> None:
    # One mug, seen close three times, then from three times as far, looking blurred.
    observations = [observation(number, 60) for number in range(3)] + [observation(3, 20)]
    cache = Embeddings({o.crop_id: SHARP for o in observations[:3]} | {"mug/3": BLURRED})
    scene = Scene("one mug", "test", 0, tuple(Sample(o.stamp, Pose.identity(), (o,)) for o in observations))

    unresolved = evaluate_identities(LookOnly, [scene], cache)
    turned_off = AnchoringConfig(far_view=FarViewConfig(scale_ratio=0.0))
    anchored_anew = evaluate_identities(LookOnly, [scene], cache, turned_off)

    assert (unresolved.anchors, unresolved.unresolved, unresolved.id_switches) == (1, 1, 0)
    assert (anchored_anew.anchors, anchored_anew.unresolved) == (2, 0)
    assert unresolved.idr < 1.0  # the unresolved view is a miss, not a match
    assert "unresolved" in format_identity_table({"far views": unresolved})
