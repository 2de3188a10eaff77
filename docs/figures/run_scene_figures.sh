#!/usr/bin/env bash
# Runs every example scene of cases/scenes/ (and again with model = "reduced" those the reduced models take: the
# canonical ones and the scenes like them; a scene with an edge, a surface or a cylinder, or without a heap or a
# fold, is refused there with exit code 2 and a message starting 'model = "reduced"', and skipped) into
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
    status=0
    "$chainsim" run "$out/$name.tmp/$name.toml" --out "${out}/${name}_reduced" >/dev/null 2>"$out/$name.tmp/err" || status=$?
    if [ "$status" -eq 0 ]; then
      "$chainsim" plot "${out}/${name}_reduced" >/dev/null
    elif [ "$status" -ne 2 ] || ! grep -q 'model = "reduced"' "$out/$name.tmp/err"; then
      cat "$out/$name.tmp/err" >&2
      exit "$status"
    fi
    rm -r "$out/$name.tmp"
  fi
done
/usr/bin/python3 docs/figures/make_scene_figures.py "$out"
