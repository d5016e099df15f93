"""Pair errors of the learned matcher and the rules by view scale, on held-out generated houses.

Why: a far view's crop is a few hundred pixels, and a scenario run (twin_moved, network, seed 0)
lost a mug's identity when a view of it from about 4 m scored as another mug. This asks whether
that is how the network behaves in general: it scores every same-class pair of Algorithm 3 in the
held-out houses (``sailor evaluate``'s pairs, twins left out: nothing can tell them apart) with
both matchers, and counts false negatives (one object taken for two) and false positives (two
taken for one) by the ratio of the percept's box to the largest view in the anchor's gallery
(the view it is compared with is the gallery's nearest), and by the percept's box alone.

Run (needs darknet's photos for the houses' textures, as ``sailor evaluate`` does)::

    SAILOR_DARKNET_DATA=$(scripts/fetch_test_data.sh) .venv/bin/python scripts/pair_errors_by_view_scale.py [SCENES]
"""

from __future__ import annotations

import sys
from dataclasses import replace

import numpy as np

from merlin2_sailor.anchoring.matcher_registry import create_matcher
from merlin2_sailor.cli.anchoring_settings import settings_from_arguments
from merlin2_sailor.cli.main import build_parser
from merlin2_sailor.cli.train_command import embedding_cache, pair_source
from merlin2_sailor.training.generated_dataset import GeneratedPairSet
from merlin2_sailor.training.pair_dataset import PairDatasetConfig
from merlin2_sailor.training.pair_scoring import chunk_features

RATIO_BINS = (0.0, 0.25, 0.35, 0.5, 0.7, 1.01, 1.5, 2.0, 3.0, np.inf)
PIXEL_BINS = (0.0, 16.0, 24.0, 32.0, 48.0, 64.0, 96.0, np.inf)


def main(scenes: int) -> int:
    arguments = build_parser().parse_args(["evaluate", "--scenes", str(scenes)])
    settings = settings_from_arguments(arguments)
    matchers = {name: create_matcher(replace(settings.matcher, name=name)) for name in ("network", "rules")}
    pair_set = GeneratedPairSet(pair_source(arguments), arguments.split, scenes, PairDatasetConfig(), arguments.first)
    cache = embedding_cache(arguments, settings.matcher.backbone)
    pair_set.embed(cache)
    short_side = {o.crop_id: min(o.region.width, o.region.height) for o in pair_set.observations()}
    columns: dict[str, list[np.ndarray]] = {"percept": [], "gallery": [], "label": [], "network": [], "rules": []}
    for chunk in pair_set.chunks():
        paper = ~(chunk.searched | chunk.replaced) & (chunk.percept_classes == chunk.anchor_classes) & ~chunk.twins
        chunk = chunk.take(np.flatnonzero(paper))
        if len(chunk) == 0:
            continue
        columns["percept"].append(np.array([short_side[c] for c in chunk.percept_crop_ids]))
        columns["gallery"].append(np.array([max(short_side[c] for c in row if c) for row in chunk.anchor_gallery_ids]))
        columns["label"].append(chunk.labels.astype(bool))
        for name, matcher in matchers.items():
            columns[name].append(matcher.score_pairs(chunk_features(chunk, matcher, cache)))
    data = {name: np.concatenate(values) for name, values in columns.items()}
    threshold = settings.core.match_threshold
    print(f"{len(data['label'])} same-class pairs of {scenes} held-out houses (split {arguments.split!r}), "
          f"threshold {threshold:g}; false negatives / positives, and their rate")
    table("percept box / largest gallery view (short sides)", data["percept"] / np.maximum(data["gallery"], 1.0),
          RATIO_BINS, data, threshold)
    table("percept box short side (pixels)", data["percept"], PIXEL_BINS, data, threshold)
    return 0


def table(title: str, values: np.ndarray, bins: tuple[float, ...], data: dict[str, np.ndarray],
          threshold: float) -> None:
    print(f"\n| {title} | pairs | same object | network FN | rules FN | network FP | rules FP |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for low, high in zip(bins[:-1], bins[1:], strict=True):
        selected = (values >= low) & (values < high)
        if not selected.any():
            continue
        label = data["label"][selected]
        cells = []
        for kind in ("FN", "FP"):
            for name in ("network", "rules"):
                said = data[name][selected] >= threshold
                wrong = (~said & label) if kind == "FN" else (said & ~label)
                base = label.sum() if kind == "FN" else (~label).sum()
                cells.append(f"{wrong.sum()} ({wrong.sum() / max(base, 1):.1%})")
        print(f"| {low:g}-{high:g} | {selected.sum()} | {label.sum()} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    raise SystemExit(main(int(sys.argv[1]) if len(sys.argv) > 1 else 10))
