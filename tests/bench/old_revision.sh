# Sourced by the side-by-side scripts (compare_revisions.sh, micro_compare.sh): an earlier revision in a
# temporary worktree, built in Release, removed again when the calling script exits.
#   old_revision_checkout OLD_REV     sets old_src (its sources) and old_build (its build directory)
#   old_revision_build TARGET...      configures and builds those targets of it
old_revision_checkout() {
  # These scripts compare git revisions, so they need git and a clone (a developer's tool: no test or CI
  # stage runs them; a source tree without .git gets this message, not git's).
  if ! command -v git >/dev/null 2>&1 || ! git rev-parse --git-dir >/dev/null 2>&1; then
    echo "comparing with revision $1 needs git and a git clone of chainsim (apt-get install git; git clone ...)" >&2
    exit 2
  fi
  old_work=$(mktemp -d)
  trap 'git worktree remove --force "$old_work/src" >/dev/null 2>&1 || true; rm -rf "$old_work"' EXIT
  git worktree add -q --detach "$old_work/src" "$1"
  old_src="$old_work/src"
  old_build="$old_work/build"
}
old_revision_build() {
  cmake -S "$old_src" -B "$old_build" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$old_build" -j "$(nproc)" --target "$@" >/dev/null
}
