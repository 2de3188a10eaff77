#!/usr/bin/env bash
# chainsim quick start: installs what is missing (Debian 12 packages), builds, then
#   demo  runs the main job: the three canonical chain problems on the string solver, as reduced ODEs and as
#         exact quadratures, a general scene, a summary table and the figures
#   test  runs the whole test suite (CTest + Catch2)
#   docs  installs the documentation tools too (Sphinx, myst-parser, numpydoc, breathe, Doxygen, nbclient,
#         nbsphinx, Chromium, ...: only for this target), builds, executes the notebooks of examples/notebooks/
#         (build/notebooks/), builds the site with warnings as errors (build/site/index.html), checks the
#         numbers the docs quote (scripts/check_doc_numbers.py) and runs every executable tests/docs/check_*
# Usage: bash scripts/quickstart.sh demo [OUTDIR]     (default OUTDIR: results)
#        bash scripts/quickstart.sh test
#        bash scripts/quickstart.sh docs
set -euo pipefail
cd "$(dirname "$0")/.."

job=${1:-}
case "$job" in
  demo|test|docs) ;;
  *) echo "usage: bash scripts/quickstart.sh demo [OUTDIR] | test | docs" >&2; exit 2 ;;
esac

# 1. Packages (all from Debian's archive). dpkg -s is quick, so a ready machine skips apt entirely.
# clang and libclang-rt-14-dev: the sanitizer build and the scene fuzzer of .ci/run (libFuzzer).
# python3-dev, pybind11-dev: the Python module chainsim; pandas, dask, distributed: its sweeps (docs/python.md);
# python3-hypothesis: the property tests of its front door (tests/python/).
packages=(cmake make g++ libeigen3-dev libsuitesparse-dev libsundials-dev catch2 libcli11-dev
          libtomlplusplus-dev nlohmann-json3-dev libfmt-dev libboost-dev libbenchmark-dev python3-matplotlib python3-numpy
          python3-pil python3-pytest python3-vtk9 ffmpeg clang libclang-rt-14-dev
          python3-dev pybind11-dev python3-pandas python3-dask python3-distributed python3-hypothesis
          python3-scipy   # chainsim fit / chainsim.fit: scipy.optimize.least_squares (docs/fit.md)
          python3-pip python3-venv python3-build python3-xarray python3-netcdf4 python3-tqdm mypy)
          # pip install . (pyproject.toml) into a venv; Result.to_xarray/to_netcdf; sweep progress bars; mypy
# The documentation site and its checks, for `docs` only (demo and test do not pay for them): Sphinx with
# myst-parser (the Markdown of docs/), numpydoc (the Python reference), breathe + Doxygen (the C++ reference),
# nbsphinx + pandoc (the gallery), nbclient + ipykernel (the notebooks), Chromium (tests/docs/ opens HTML in it
# headless).
if [ "$job" = docs ]; then
  packages+=(python3-sphinx python3-myst-parser python3-numpydoc python3-breathe doxygen python3-sphinx-rtd-theme
             python3-nbsphinx pandoc python3-nbclient python3-nbformat python3-nbconvert python3-ipykernel
             chromium)
fi
missing=()
for p in "${packages[@]}"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
if [ ${#missing[@]} -gt 0 ]; then
  echo "== installing: ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  # apt's own progress (one line per package fetched and set up), so that minutes of downloads show.
  $sudo apt-get update
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y --no-install-recommends -o Dpkg::Use-Pty=0 "${missing[@]}"
fi

# 2. Build (Release).
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
if [ "$job" = demo ]; then
  cmake --build build -j "$jobs" --target chainsim
elif [ "$job" = docs ]; then
  cmake --build build -j "$jobs" --target chainsim chainsim_python
else
  cmake --build build -j "$jobs"
fi

# 3. The job.
if [ "$job" = demo ]; then
  out=${2:-results}
  ./build/chainsim canonical --out "$out"
  # A general scene beyond the reduced model: a chain released curved, its contact sliding on the table.
  scene=cases/scenes/curved_falling_chain.toml
  ./build/chainsim run "$scene" --out "$out/$(basename "$scene" .toml)"
  # Debian's python3 has matplotlib; a python3 earlier on PATH may not.
  /usr/bin/python3 scripts/plot_canonical.py "$out" --scene "$scene"
elif [ "$job" = docs ]; then
  py=/usr/bin/python3
  echo "== notebooks (nbclient)"
  $py scripts/run_notebooks.py --build build
  echo "== site (Doxygen XML, then Sphinx -W into build/site)"
  rm -rf build/doxygen && mkdir -p build/doxygen
  CHAINSIM_DOXYGEN_OUT=build/doxygen doxygen docs/Doxyfile
  CHAINSIM_BUILD_DIR=build $py -m sphinx -b html -E -W --keep-going -q docs build/site
  echo "site     build/site/index.html"
  echo "== numbers quoted in the docs"
  $py scripts/check_doc_numbers.py --build build
  for check in tests/docs/check_*; do   # every executable check there (the pattern may match none)
    [ -x "$check" ] || continue
    echo "== $check"
    CHAINSIM_BUILD_DIR=build "$check"
  done
else
  ctest --test-dir build --output-on-failure -j "$jobs"
fi
