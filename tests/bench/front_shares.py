#!/usr/bin/env python3
"""Shares of a front run's time by what it was doing, from a `perf record --call-graph dwarf` profile.

Usage:
    perf record --call-graph dwarf,16384 -F 2000 -o front.data \\
        build/chainsim run cases/scenes/falling_chain.toml --set string.nodes=301 --out /tmp/fc --quiet
    /usr/bin/python3 tests/bench/front_shares.py front.data [more.data ...]

Each sample goes to the first category (outermost frame first) whose function it passes through:
  polish         Integrator::polish_event: the step that holds a crossing recomputed to the root
  handle_events  StringModel::handle_events: the crossing itself (material moved, arcs rebuilt, projection)
  reinit         restart/resize after a crossing and ARKODE's set-up of the next first step
  rootfinding    ARKODE's search for roots after every step (arkRootCheck*, arkRootfind)
  outputs        frames, step records and the files
  steps          ARKODE's steps between crossings
  other          the rest (start-up, scene parsing, ...)
With several profiles, prints the median share of each category (and the spread).
"""
import collections
import statistics
import subprocess
import sys

CATEGORIES = [
    ("polish", ["polish_event"]),
    ("handle_events", ["EE13handle_events"]),
    ("reinit", ["ARKStepReset", "ARKStepResize", "arkInitialSetup", "ARKStepRootInit",
                "Integrator7restart", "Integrator6resize"]),
    ("rootfinding", ["arkRootCheck", "arkRootfind"]),
    ("outputs", ["record_frame", "record_sample", "write_outputs", "projected_state"]),
    ("steps", ["arkStep_TakeStep", "arkCompleteStep", "arkStep_FullRHS"]),
]


def shares(path):
    """{category: per cent of the samples} of one profile, and the number of samples."""
    text = subprocess.run(["perf", "script", "-i", path, "-F", "comm,ip,sym", "--no-demangle"],
                          capture_output=True, text=True, check=True).stdout
    counts, total = collections.Counter(), 0
    for block in text.split("\n\n"):
        lines = block.strip().splitlines()
        frames = [line.split()[1] for line in lines[1:] if len(line.split()) > 1]
        if not frames:
            continue
        total += 1
        category = "other"
        for frame in reversed(frames):  # outermost first
            hit = next((name for name, keys in CATEGORIES if any(k in frame for k in keys)), None)
            if hit:
                category = hit
                break
        counts[category] += 1
    if total == 0:
        sys.exit(f"{path}: no samples with call graphs")
    return {name: 100.0 * counts[name] / total for name, _ in CATEGORIES + [("other", None)]}, total


def main(paths):
    if not paths:
        sys.exit(__doc__)
    runs = [shares(p) for p in paths]
    for name, _ in CATEGORIES + [("other", None)]:
        values = [r[0][name] for r in runs]
        spread = f"  ({min(values):.1f} - {max(values):.1f})" if len(values) > 1 else ""
        print(f"{name:14s} {statistics.median(values):6.1f} %{spread}")
    print(f"samples        {statistics.median([r[1] for r in runs]):.0f} (median of {len(runs)} profiles)")


if __name__ == "__main__":
    main(sys.argv[1:])
