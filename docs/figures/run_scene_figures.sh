#!/usr/bin/env bash
# Runs every example scene of cases/scenes/ (and the canonical ones again with model = "reduced") into
# RESULTS_DIR, draws each run with `chainsim plot` (RESULTS_DIR/<scene>/figures/), then draws
# docs/figures/scene_<scene>.png with make_scene_figures.py (the same package's snapshots and ledger, and
# the quantity each scene is about).
# Usage: bash docs/figures/run_scene_figures.sh [RESULTS_DIR] [CHAINSIM]   (defaults: results/scenes, build/chainsim)
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-results/scenes}
chainsim=${2:-build/chainsim}
for scene in cases/scenes/*.toml; do
  name=$(basename "$scene" .toml)
  "$chainsim" run "$scene" --out "$out/$name" >/dev/null
  "$chainsim" plot "$out/$name" >/dev/null
  if grep -q '^model = "string"' "$scene"; then
    mkdir -p "$out/$name.tmp"
    sed 's/^model = "string"/model = "reduced"/' "$scene" >"$out/$name.tmp/$name.toml"
    "$chainsim" run "$out/$name.tmp/$name.toml" --out "${out}/${name}_reduced" >/dev/null
    "$chainsim" plot "${out}/${name}_reduced" >/dev/null
    rm -r "$out/$name.tmp"
  fi
done
/usr/bin/python3 docs/figures/make_scene_figures.py "$out"
