#!/usr/bin/python3
"""Draws the main job's figures from the data written by `chainsim canonical --out DIR`.

Usage: /usr/bin/python3 scripts/plot_canonical.py DIR [--scene SCENE.toml]
Writes DIR/figures/*.png: fall_time_vs_f.png, {falling,folded,sliding}_chain.png,
{falling,folded,sliding}_snapshots.png and agreement.png, as `chainsim plot DIR` does; with --scene (a scene
run by `chainsim run SCENE --out DIR/<scene file stem>`) also DIR/figures/<stem>.png. The drawing is the
package python/chainsim_plot (canonical.py, which lists what each figure shows). Needs Debian's
python3-matplotlib. Exit code 2 for a missing or malformed input file.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))

from chainsim_plot.canonical import canonical_figures  # noqa: E402
from chainsim_plot.readers import RunError  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description="Draws the figures of `chainsim canonical --out DIR`.")
    parser.add_argument("dir", help="DIR as given to chainsim canonical --out")
    parser.add_argument("--scene", help="a scene file also run with `chainsim run SCENE --out DIR/<stem>`")
    args = parser.parse_args()
    out_dir = os.path.join(args.dir, "figures")
    try:
        written = canonical_figures(args.dir, out_dir, args.scene)
    except RunError as e:
        sys.stderr.write(f"plot_canonical.py: error: {e}\n")
        return 2
    print(f"figures  {out_dir}: " + ", ".join(sorted(os.path.basename(p) for p in written)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
