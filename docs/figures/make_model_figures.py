#!/usr/bin/python3
"""Schematic of the three canonical chain problems for docs/model.md.

Run:  /usr/bin/python3 docs/figures/make_model_figures.py
Writes docs/figures/model_geometries.png (a line drawing; no data, no solver output).
"""
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
CHAIN = dict(color="k", lw=2.5, solid_capstyle="round")
THIN = dict(color="0.35", lw=0.9)


def heap(ax, x0, y0, n=22, w=0.5, h=0.16, seed=1):
    """Quiescent links (the reservoir) drawn as scattered dots."""
    rng = np.random.default_rng(seed)
    xs = x0 + w * (rng.random(n) - 0.5)
    ys = y0 + 0.02 + h * rng.random(n) * (1 - np.abs(xs - x0) / (0.6 * w))
    ax.plot(xs, ys, "o", color="k", ms=3)


def dim(ax, x, y_a, y_b, label, side=-1):
    """Vertical dimension arrow from y_a to y_b at abscissa x."""
    ax.annotate("", xy=(x, y_b), xytext=(x, y_a),
                arrowprops=dict(arrowstyle="<->", color="0.3", lw=0.9))
    ax.text(x + side * 0.07, 0.5 * (y_a + y_b), label, ha="right" if side < 0 else "left",
            va="center", fontsize=12)


def s_arrow(ax, x, y, dx, dy):
    ax.annotate("", xy=(x + dx, y + dy), xytext=(x, y),
                arrowprops=dict(arrowstyle="->", color="tab:blue", lw=1.4))
    ax.text(x + dx + 0.03 * np.sign(dx), y + dy + 0.02 * np.sign(dy), "$s$", color="tab:blue",
            fontsize=12, ha="left" if dx >= 0 else "right", va="bottom" if dy >= 0 else "top")


def shock(ax, x, y, label, dx=0.06, dy=-0.07, ha="left"):
    ax.plot([x], [y], "o", mfc="white", mec="tab:red", mew=1.6, ms=8, zorder=5)
    ax.text(x + dx, y + dy, label, color="tab:red", fontsize=11, ha=ha, va="center")


def frame(ax, title):
    ax.set_aspect("equal")
    ax.axis("off")
    ax.set_title(title, fontsize=12)


def main():
    fig, axes = plt.subplots(1, 3, figsize=(11, 4.6))

    # (a) falling chain: s from the free (top) end down to the table; y = height of the falling part.
    ax = axes[0]
    ax.fill_between([-0.8, 0.8], -0.08, 0.0, color="0.85")
    ax.plot([-0.8, 0.8], [0, 0], **THIN)
    y = 0.95
    ax.plot([0, 0], [0, y], **CHAIN)
    ax.plot([0, 0.08], [0, 0], **CHAIN)
    heap(ax, 0.22, 0.0, seed=2)
    shock(ax, 0, 0, r"$x_0$, $x^\ast_+$", dx=-0.08, dy=0.12, ha="right")
    s_arrow(ax, 0.08, 0.9, 0.0, -0.25)
    dim(ax, -0.3, 0.0, y, "$y$")
    ax.text(0.05, y + 0.04, "free end, $s=0$", fontsize=10, va="bottom")
    ax.annotate("", xy=(0.55, 0.55), xytext=(0.55, 0.8),
                arrowprops=dict(arrowstyle="->", color="0.3"))
    ax.text(0.6, 0.68, "$g$", fontsize=12)
    ax.text(0.35, -0.2, "table, heap of $\\ell-y$", fontsize=10, ha="center")
    ax.set_xlim(-0.8, 0.8)
    ax.set_ylim(-0.3, 1.15)
    frame(ax, "(a) falling chain")

    # (b) folded chain: s from the fixed end; y = length of the resting arm; F up on the free end.
    ax = axes[1]
    ell, y = 1.0, 0.62
    top = 1.0
    gap = 0.07
    ax.plot([-0.25, 0.25], [top, top], **THIN)
    for xh in np.linspace(-0.22, 0.2, 8):
        ax.plot([xh, xh + 0.05], [top, top + 0.05], **THIN)
    bight = top - y
    tip = bight + (ell - y)
    ax.plot([-gap, -gap], [top, bight], **CHAIN)
    th = np.linspace(np.pi, 2 * np.pi, 30)
    ax.plot(gap * np.cos(th), bight + gap * np.sin(th), **CHAIN)
    ax.plot([gap, gap], [bight, tip], **CHAIN)
    ax.plot([-gap], [top], "ks", ms=6)
    shock(ax, 0, bight - gap, "$x_0$ (bight)", dx=0.1, dy=-0.04)
    s_arrow(ax, -0.17, top - 0.05, 0.0, -0.25)
    dim(ax, -0.35, top, bight - gap, "$y$")
    dim(ax, 0.6, bight - gap, tip, r"$\ell-y$", side=+1)
    ax.annotate("", xy=(gap, tip + 0.22), xytext=(gap, tip),
                arrowprops=dict(arrowstyle="->", color="tab:green", lw=1.6))
    ax.text(gap + 0.04, tip + 0.14, "$F$", color="tab:green", fontsize=12)
    ax.text(gap + 0.04, tip - 0.03, "free end, $s=\\ell$", fontsize=10, va="top", ha="left")
    ax.text(-gap - 0.04, top + 0.08, "fixed end, $s=0$", fontsize=10, ha="center", va="bottom")
    ax.set_xlim(-0.8, 0.8)
    ax.set_ylim(-0.3, 1.25)
    frame(ax, "(b) folded chain")

    # (c) sliding chain: s from the heap through the hole to the free end at s = l; y = hanging length.
    ax = axes[2]
    ax.fill_between([-0.8, -0.03], 0.72, 0.8, color="0.85")
    ax.fill_between([0.03, 0.8], 0.72, 0.8, color="0.85")
    ax.plot([-0.8, -0.03], [0.8, 0.8], **THIN)
    ax.plot([0.03, 0.8], [0.8, 0.8], **THIN)
    y = 0.75
    ax.plot([-0.3, 0], [0.8, 0.8], **CHAIN)
    ax.plot([0, 0], [0.8, 0.8 - y], **CHAIN)
    heap(ax, -0.58, 0.8, w=0.4, seed=5)
    shock(ax, -0.3, 0.8, r"$x^\ast_-$", dx=0.0, dy=0.13, ha="center")
    s_arrow(ax, -0.28, 0.86, 0.2, 0.0)
    shock(ax, 0, 0.8, "$x_0$ (hole)", dx=0.08, dy=0.12)
    s_arrow(ax, 0.08, 0.6, 0.0, -0.25)
    dim(ax, -0.25, 0.8, 0.8 - y, "$y$")
    ax.text(0.05, 0.8 - y - 0.03, "free end, $s=\\ell$", fontsize=10, va="top")
    ax.text(-0.58, 1.02, "heap", fontsize=10, ha="center")
    ax.set_xlim(-0.8, 0.8)
    ax.set_ylim(-0.3, 1.2)
    frame(ax, "(c) sliding chain")

    fig.tight_layout()
    out = os.path.join(HERE, "model_geometries.png")
    fig.savefig(out, dpi=130, bbox_inches="tight")
    print(out)


if __name__ == "__main__":
    main()
