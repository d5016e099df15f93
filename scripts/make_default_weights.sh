#!/usr/bin/env bash
# Make the matching-network weights that ship in merlin2_sailor/models/, from the house source
# (tours of generated houses rendered by the simulated world, none of them the demo's: see
# demos/identity/house_source.py), then evaluate them on held-out test houses (pairs, with the
# rule matcher beside them) and on tours of the demo's house (duplicates, identity switches).
# Deterministic given the seed (up to floating-point differences between machines).
# Rendered scenes and embeddings are cached under $SAILOR_CACHE (default ~/.cache/merlin2_sailor),
# so a second run renders and embeds nothing.
# Usage: scripts/make_default_weights.sh            (about 17 minutes on 2 CPU cores, 4 when cached; then 2 minutes of tours)
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
python="${PYTHON:-$root/.venv/bin/python}"
export SAILOR_DARKNET_DATA="${SAILOR_DARKNET_DATA:-$(scripts/fetch_test_data.sh)}"
if [ ! -f "$SAILOR_DARKNET_DATA/dog.jpg" ]; then
  echo "make_default_weights: darknet photos not found (scripts/fetch_test_data.sh failed)" >&2
  exit 1
fi
weights="merlin2_sailor/models/matching_network_efficientnet_lite0.pt"

"$python" -m merlin2_sailor.cli.main train --source houses --seed 0 --output "$weights"
# The loss curve is a build product, not package data: keep it in build/.
mkdir -p build/default_weights
mv -f "${weights%.pt}_loss.png" build/default_weights/loss.png
"$python" -m merlin2_sailor.cli.main evaluate --source houses --seed 0 --weights "$weights" \
  --output build/default_weights
"$python" -m merlin2_sailor.cli.main evaluate --world worlds/house.yaml --world-seeds 0,1,2 --launch demo \
  --weights "$weights" --output build/default_weights
