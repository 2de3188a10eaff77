#!/usr/bin/env bash
# The animations of docs/scenes.md (slack and snap-taut, the chain off the table's edge and off a real table, the
# pulleys, landings, a heap on a table, the pegs, a string drawn onto a table in 2D and 3D): runs
# cases/scenes/{swinging_u,pendulum_whip,thrown_chain,chain_off_table_edge,chain_off_real_table,atwood_pulley,
# chain_lifting_off_pulley,atwood_rough_pulley,chain_over_round_peg,chain_landing_at_angle,chain_into_heap_on_table,chain_over_peg,chain_over_two_pegs,
# chain_drawn_onto_table,chain_drawn_onto_table_3d,chain_landing_on_table}.toml into RESULTS_DIR and animates
# each with `chainsim plot RUN --animate --format gif --fps 15 --speed 0.25` (a quarter of real time, 15 frames
# per second: 61 frames for a 1 s run; the contact scenes are short, 0.3 to 0.75 s, so all keep a quarter of real
# time; a scene recording frames less often than every speed/fps = 1/60 s shows each recorded frame for several
# video frames, and Pillow merges repeated frames), copied from RESULTS_DIR/<scene>/figures/animation.gif to
# docs/figures/<scene>_animation.gif.
# Usage: bash docs/figures/run_scene_animations.sh [RESULTS_DIR] [CHAINSIM]   (defaults: results/animations, build/chainsim)
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-results/animations}
chainsim=${2:-build/chainsim}
for name in swinging_u pendulum_whip thrown_chain chain_off_table_edge chain_off_real_table atwood_pulley chain_lifting_off_pulley \
    atwood_rough_pulley chain_over_round_peg chain_landing_at_angle chain_into_heap_on_table chain_over_peg chain_over_two_pegs chain_drawn_onto_table \
    chain_drawn_onto_table_3d chain_landing_on_table; do
  "$chainsim" run "cases/scenes/$name.toml" --out "$out/$name" >/dev/null
  "$chainsim" plot "$out/$name" --animate --format gif --fps 15 --speed 0.25 >/dev/null
  cp "$out/$name/figures/animation.gif" "docs/figures/${name}_animation.gif"
done
