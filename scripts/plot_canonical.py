#!/usr/bin/python3
"""Draws the paper's figures from the data written by `chainsim canonical --out DIR`.

Usage: /usr/bin/python3 scripts/plot_canonical.py DIR
Writes DIR/figures/{fall_time_vs_f,falling_chain,folded_chain,sliding_chain}.png with the package
python/chainsim_plot (`chainsim plot DIR` draws these and the figures of each problem's run). Needs
Debian's python3-matplotlib.
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))

from chainsim_plot.canonical import paper_figures  # noqa: E402
from chainsim_plot.readers import RunError  # noqa: E402


def main():
    if len(sys.argv) != 2:
        sys.stderr.write("usage: plot_canonical.py DIR   (DIR as given to chainsim canonical --out)\n")
        sys.exit(2)
    root = sys.argv[1]
    out_dir = os.path.join(root, "figures")
    try:
        paper_figures(root, out_dir)
    except RunError as e:
        sys.stderr.write(f"plot_canonical.py: error: {e}\n")
        sys.exit(2)
    print(f"wrote the figures in {out_dir}")


if __name__ == "__main__":
    main()
