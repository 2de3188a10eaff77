#!/usr/bin/env bash
# chainsim installed with pip, offline, as a new user installs it (docs/python.md, "Install with pip"):
#   1. a fresh virtual environment (--system-site-packages: Debian's numpy, matplotlib, pandas, ...), then
#      `pip install --no-build-isolation .` from the source tree (the build runs CMake: pyproject.toml);
#      the tour of docs/python.md runs unchanged there (taken from the page), from a directory outside the
#      source tree, importing the installed package; the installed `chainsim` runs, and its `chainsim plot`
#      draws with the installed plotting tool;
#   2. `pip wheel --no-build-isolation .`, the wheel installed into a second fresh environment with
#      `pip install --no-index`, and an example (examples/read_cli_run.py) run with it.
# Every pip command runs with --no-index: nothing is downloaded. Prints the time of each pip command.
# Run by the docs stage of CI (`bash scripts/quickstart.sh docs` runs every tests/docs/check_*); by hand:
#   bash tests/docs/check_pip_install.sh            (PYTHON=/path/to/python3 for another interpreter with numpy)
# The CMake build of the wheel is kept in build/wheel-<tag>/ (a second run rebuilds only what changed).
set -euo pipefail
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
python=${PYTHON:-/usr/bin/python3}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
unset PYTHONPATH
export PIP_NO_INDEX=1 PIP_DISABLE_PIP_VERSION_CHECK=1 MPLBACKEND=Agg
say() { echo "check_pip_install: $*"; }
timed() {  # timed LABEL COMMAND...: runs it, prints its wall time, shows its output only if it fails
  local label=$1 start end; shift
  start=$EPOCHREALTIME
  if ! "$@" >"$tmp/log" 2>&1; then cat "$tmp/log"; say "FAILED: $label"; exit 1; fi
  end=$EPOCHREALTIME
  say "$(awk -v l="$label" -v a="$start" -v b="$end" 'BEGIN { printf "%-58s %6.1f s", l, b - a }')"
}

# 1. pip install . into a fresh environment
timed "$python -m venv --system-site-packages" "$python" -m venv --system-site-packages "$tmp/venv"
cd "$source_dir"
timed "pip install --no-build-isolation ." "$tmp/venv/bin/pip" install --no-build-isolation .
mkdir "$tmp/tour" && ln -s "$source_dir/cases" "$tmp/tour/cases"
"$python" - "$source_dir/docs/python.md" > "$tmp/tour/tour.py" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
tour = text[text.index("\n## A tour"):]
print(re.search(r"```python\n(.*?)```", tour, re.S).group(1))
PY
cat >> "$tmp/tour/tour.py" <<'PY'
import os, sys
assert chainsim.__file__.startswith(sys.prefix), f"imported {chainsim.__file__}, not the installed package"
print("the tour ran with", chainsim.__file__, chainsim.__version__)
PY
cd "$tmp/tour"
timed "the tour of docs/python.md (installed package)" "$tmp/venv/bin/python" tour.py
grep "the tour ran" "$tmp/log" | sed 's/^/check_pip_install: /'
test "$("$tmp/venv/bin/chainsim" --version)" = "$("$tmp/venv/bin/python" -c 'import chainsim; print(chainsim._core.version_text)')"
timed "installed chainsim plot --animate --html" "$tmp/venv/bin/chainsim" plot results/falling --animate --html --fps 5
test -f results/falling/figures/animation.html

# 2. pip wheel ., the wheel into a second fresh environment, an example
cd "$source_dir"
timed "pip wheel --no-build-isolation . (the same build)" "$tmp/venv/bin/pip" wheel --no-build-isolation --no-deps -w "$tmp/wheels" .
wheel=$(ls "$tmp"/wheels/chainsim-*.whl)
say "wheel $(basename "$wheel") ($(du -k "$wheel" | cut -f1) kB)"
timed "$python -m venv --system-site-packages (second)" "$python" -m venv --system-site-packages "$tmp/venv2"
timed "pip install the wheel" "$tmp/venv2/bin/pip" install "$wheel"
cd "$tmp"
timed "examples/read_cli_run.py --quick (wheel)" env CHAINSIM_BINARY="$tmp/venv2/bin/chainsim" \
  CHAINSIM_EXAMPLE_OUT="$tmp/example" "$tmp/venv2/bin/python" "$source_dir/examples/read_cli_run.py" --quick
test -f "$tmp/example/whip_crack/figures/energy.png"
say "ok"
