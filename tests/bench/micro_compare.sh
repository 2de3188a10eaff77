#!/usr/bin/env bash
# Side by side in one run: the micro-benchmarks (chainsim_bench_micro, Google Benchmark) of an earlier
# revision against the current build. If the earlier revision has no tests/bench/bench_micro.cpp, the
# current benchmark source is built against the earlier revision's libraries (same API needed). The two
# binaries then run alternately (old, new, old, new, …), so that drifts of a shared machine hit both
# alike; printed: the median CPU and real time per iteration of each benchmark, and the ratios new/old
# (on a loaded machine the CPU time is the steadier of the two).
#
# Usage: bash tests/bench/micro_compare.sh OLD_REV [ROUNDS] [FILTER]   (from the repository root, after
#        `cmake --build build --target chainsim_bench_micro`; ROUNDS default 5; FILTER a
#        --benchmark_filter regex, default all)
set -euo pipefail
old_rev=${1:?usage: micro_compare.sh OLD_REV [ROUNDS] [FILTER]}
rounds=${2:-5}
filter=${3:-.}
new_bin=build/tests/chainsim_bench_micro
[ -x "$new_bin" ] || { echo "build $new_bin first (needs Debian's libbenchmark-dev)" >&2; exit 2; }
here=$(cd "$(dirname "$0")" && pwd)
source "$here/old_revision.sh"
old_revision_checkout "$old_rev"
if [ ! -f "$old_src/tests/bench/bench_micro.cpp" ]; then
  echo "== $old_rev has no bench_micro.cpp: building the current one against its libraries"
  cp "$here/bench_micro.cpp" "$old_src/tests/bench/"
  # the CMake block of the current tests/CMakeLists.txt that builds it
  sed -n '/^# chainsim_bench_micro:/,/^endif()/p' "$here/../CMakeLists.txt" >> "$old_src/tests/CMakeLists.txt"
fi
old_revision_build chainsim_bench_micro
old_bin="$old_build/tests/chainsim_bench_micro"
out=$(mktemp -d)
for ((r = 0; r < rounds; ++r)); do
  for which in old new; do
    bin=$old_bin; [ "$which" = new ] && bin=$new_bin
    "$bin" --benchmark_filter="$filter" --benchmark_min_time=0.2 --benchmark_format=json \
      --benchmark_out="$out/$which.$r.json" >/dev/null
  done
done
new_rev=$(git rev-parse --short HEAD 2>/dev/null || echo "working tree")  # a tree without git (a source copy) has no revision
/usr/bin/python3 - "$out" "$rounds" "$old_rev" "$new_rev" <<'PY'
import json, statistics, sys, collections
out, rounds, old_rev, new_rev = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
t = collections.defaultdict(list)  # (which, name, "cpu" | "real") -> microseconds per iteration
order = []
for which in ("old", "new"):
    for r in range(rounds):
        for b in json.load(open(f"{out}/{which}.{r}.json"))["benchmarks"]:
            if b.get("error_occurred"):
                continue
            scale = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}[b["time_unit"]]
            for kind in ("cpu", "real"):
                t[(which, b["name"], kind)].append(b[kind + "_time"] * scale)
            if b["name"] not in order:
                order.append(b["name"])
print(f"old = {old_rev}, new = {new_rev}; medians of {rounds} alternating rounds, microseconds per iteration")
print(f"{'benchmark':28s} {'old cpu':>10s} {'new cpu':>10s} {'new/old':>8s}   {'old real':>10s} {'new real':>10s} {'new/old':>8s}")
for name in order:
    cells = []
    for kind in ("cpu", "real"):
        o, n = t[("old", name, kind)], t[("new", name, kind)]
        if o and n:
            mo, mn = statistics.median(o), statistics.median(n)
            cells.append(f"{mo:10.3f} {mn:10.3f} {mn / mo:8.3f}")
        else:
            cells.append(f"{'–' if not o else f'{statistics.median(o):.3f}':>10s} {'–' if not n else f'{statistics.median(n):.3f}':>10s} {'':>8s}")
    print(f"{name:28s} {cells[0]}   {cells[1]}")
PY
rm -rf "$out"
