#!/usr/bin/env bash
# Where an implicit step's instructions go (docs/string_solver.md, "What remains of a step, and its
# floor"): callgrind counts instructions, which a shared machine does not perturb, on one run of
# chainsim_bench_modes (three periods of the hanging chain's first mode), and this prints the total per
# step and the inclusive shares of the Newton solves, the right-hand sides, the Newton set-ups and
# ARKODE's vector operations (the Eigen kernels of solver/nvector_kernels.cpp and SUNDIALS' own).
#
# Usage: bash tests/bench/implicit_step_profile.sh [CASE] [BINARY]   (from the repository root, after
#        `cmake --build build --target chainsim_bench_modes`; CASE default dirk4:1e-6:250, as
#        METHOD:RTOL:LINKS; BINARY default build/tests/chainsim_bench_modes, e.g. an older build's)
set -euo pipefail
case_=${1:-dirk4:1e-6:250}
bin=${2:-build/tests/chainsim_bench_modes}
[ -x "$bin" ] || { echo "build $bin first" >&2; exit 2; }
command -v valgrind >/dev/null || { echo "needs valgrind (Debian: valgrind)" >&2; exit 2; }
out=$(mktemp -d)
valgrind --tool=callgrind --callgrind-out-file="$out/cg.out" "$bin" --repeats 1 "$case_" >"$out/run.txt" 2>"$out/vg.txt"
cat "$out/run.txt"
steps=$(awk 'NR == 2 {print $4}' "$out/run.txt")
callgrind_annotate --inclusive=yes "$out/cg.out" >"$out/incl.txt" 2>/dev/null
callgrind_annotate "$out/cg.out" >"$out/self.txt" 2>/dev/null
# The Ir of the first line whose symbol matches the pattern (commas removed).
ir() { grep -E "$2" "$1" | head -1 | awk '{gsub(",", "", $1); print $1 + 0}'; }
total=$(grep "PROGRAM TOTALS" "$out/incl.txt" | awk '{gsub(",", "", $1); print $1}')
solve=$(ir "$out/incl.txt" 'Integrator::Impl::newton_solve')
rhs=$(ir "$out/incl.txt" 'Integrator::Impl::rhs')
setup=$(ir "$out/incl.txt" 'Integrator::Impl::newton_linearize')
# Vector operations: the self cost of every kernel of nvector_kernels.cpp and of SUNDIALS' serial ones.
vec=$(grep -E "anonymous namespace\)::(linear_sum|linear_combination|scale_add_multi|weighted_square_sum|wrms_norm|scale|constant|absolute|inverse|add_constant)\(|_Serial " "$out/self.txt" |
  awk '{gsub(",", "", $1); s += $1} END {print s + 0}')
awk -v t="$total" -v n="$steps" -v a="$solve" -v b="$rhs" -v c="$setup" -v d="$vec" 'BEGIN {
  printf "instructions: %.1f M in all, %.2f M per step (%d steps)\n", t / 1e6, t / 1e6 / n, n
  printf "  Newton solves     %5.1f %%  %.2f M per step\n", 100 * a / t, a / 1e6 / n
  printf "  right-hand sides  %5.1f %%  %.2f M per step\n", 100 * b / t, b / 1e6 / n
  printf "  Newton set-ups    %5.1f %%  %.2f M per step\n", 100 * c / t, c / 1e6 / n
  printf "  vector operations %5.1f %%  %.2f M per step\n", 100 * d / t, d / 1e6 / n
}'
rm -rf "$out"
