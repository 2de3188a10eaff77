#!/usr/bin/env bash
# Side by side in one run: chainsim_bench_scene of an earlier revision against the current build.
# Builds the earlier revision's benchmark in a temporary worktree (Release), then runs the two
# binaries alternately (old, new, old, new, …) so that drifts of a noisy machine hit both alike,
# and prints the median integration time of each scene kind and the ratio new/old.
#
# Usage: bash tests/bench/compare_revisions.sh OLD_REV [ROUNDS]     (from the repository root,
#        after `cmake --build build --target chainsim_bench_scene`)
set -euo pipefail
old_rev=${1:?usage: compare_revisions.sh OLD_REV [ROUNDS]}
rounds=${2:-7}
new_bin=build/tests/chainsim_bench_scene
[ -x "$new_bin" ] || { echo "build $new_bin first" >&2; exit 2; }
source "$(dirname "$0")/old_revision.sh"
old_revision_checkout "$old_rev"
old_revision_build chainsim_bench_scene
old_bin="$old_build/tests/chainsim_bench_scene"
# One line per run and kind: "<old|new> <kind> <run ms>".
for ((r = 0; r < rounds; ++r)); do
  for which in old new; do
    bin=$old_bin; [ "$which" = new ] && bin=$new_bin
    "$bin" --quick | awk -v w="$which" '/^  \((i|ii|iii)\)/ { k = $1; for (i = 2; i <= NF; ++i) if ($i ~ /^[0-9.]+$/) { print w, k, $i; break } }'
  done
done | /usr/bin/python3 -c '
import sys, statistics, collections
t = collections.defaultdict(list)
for line in sys.stdin:
    w, k, ms = line.split()
    t[(w, k)].append(float(ms))
rounds = len(t[("old", "(i)")])
print("%-8s %10s %10s %8s   medians of the run time over %d alternating rounds" % ("scene", "old (ms)", "new (ms)", "new/old", rounds))
for k in ("(i)", "(ii)", "(iii)"):
    o, n = statistics.median(t[("old", k)]), statistics.median(t[("new", k)])
    print("%-8s %10.2f %10.2f %8.3f" % (k, o, n, n / o))
'
