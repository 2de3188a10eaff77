#!/usr/bin/env bash
# `cmake --install` into a temporary prefix, then: the installed executable runs, `import chainsim` from
# the prefix works (and runs), and an external CMake project finds the package (find_package(chainsim),
# chainsim::chainsim), builds and runs (consumer.cpp checks its own numbers).
# Usage: test_install.sh BUILD_DIR PYTHON PYTHON_DIR (PYTHON_DIR: the packages' directory under the prefix)
set -euo pipefail
build=$1 python=$2 pydir=$3
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
cmake --install "$build" --prefix "$prefix" >/dev/null
test -x "$prefix/bin/chainsim"
"$prefix/bin/chainsim" --version
test -f "$prefix/lib/cmake/chainsim/chainsimConfig.cmake"
test -f "$prefix/include/chainsim/solver/string_solver.hpp"
test -f "$prefix/$pydir/chainsim_plot/__main__.py"
if [ -d "$prefix/$pydir/chainsim" ]; then
  (cd "$tmp" && env -u PYTHONPATH PYTHONPATH="$prefix/$pydir" "$python" -c '
import os, sys, chainsim
assert chainsim.__file__.startswith(sys.argv[1]), chainsim.__file__
r = chainsim.reduced("falling", f=0.5)
assert abs(r.summary["t_stop_over_t0"] - r.summary["t_stop_over_t0_exact"]) < 1e-9
import chainsim_plot
print("import chainsim from", os.path.dirname(chainsim.__file__))' "$prefix")
  # the installed `chainsim fit` runs the installed package (cases/cli/python_command.cpp), with SciPy
  if "$python" -c "import scipy" 2>/dev/null; then
    (cd "$tmp" && env -u PYTHONPATH "$prefix/bin/chainsim" fit falling "$here/../../examples/data/falling_chain_height.csv" \
       --free f=0.5 --free t_offset=0:-0.1:0.1 --set length=1 --set density=0.1 --profile none --no-figures \
       --out "$tmp/fit" >/dev/null)
    test -f "$tmp/fit/fit.json"
  fi
fi
cmake -S "$here" -B "$tmp/consumer" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$tmp/consumer" >/dev/null
"$tmp/consumer/consumer"
