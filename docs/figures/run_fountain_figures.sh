#!/usr/bin/env bash
# The chain fountain's figures (docs/scenes.md): runs cases/scenes/chain_fountain.toml and the same fountain started
# off its steady state (docs/figures/fountain.py scene --shape-pot-f -0.1 --speed-factor 0.9: 10 % slow, on the
# steady shape of a weaker pot, 16 m in the pot) into RESULTS_DIR, draws docs/figures/fountain.png (shape, speed,
# rise against the closed form) and animates the off start with `chainsim plot --animate`
# (RESULTS_DIR/chain_fountain_off/figures/animation.*), copied to docs/figures/fountain_animation.*.
# Usage: bash docs/figures/run_fountain_figures.sh [RESULTS_DIR] [CHAINSIM]   (defaults: results/fountain, build/chainsim)
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-results/fountain}
chainsim=${2:-build/chainsim}
mkdir -p "$out"
/usr/bin/python3 docs/figures/fountain.py scene --shape-pot-f -0.1 --speed-factor 0.9 --pot-content 16 --nodes 1201 \
  >"$out/chain_fountain_off.toml"
"$chainsim" run cases/scenes/chain_fountain.toml --out "$out/chain_fountain" >/dev/null
"$chainsim" run "$out/chain_fountain_off.toml" --out "$out/chain_fountain_off" >/dev/null
/usr/bin/python3 docs/figures/fountain.py figures "$out"
"$chainsim" plot "$out/chain_fountain_off" --animate --format gif --fps 10 --speed 1 >/dev/null
cp "$out/chain_fountain_off/figures/animation.gif" docs/figures/fountain_animation.gif
